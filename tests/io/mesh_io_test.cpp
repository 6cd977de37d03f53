// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/io/mesh_io.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "io_test_util.h"
#include "test_util.h"
#include "zomefab/io/file_io.h"

using namespace zomefab;
using namespace zomefab::test;

namespace {

template <typename T>
void put(std::string& s, T v, bool bigEndian = false) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (bigEndian)
        for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    s.append(b, sizeof(T));
}

/// Binary STL of @p mesh with a custom 80-byte header and optionally a wrong triangle count.
std::string binaryStl(const TriMesh& mesh, const std::string& header, uint32_t count) {
    std::string s = header;
    s.resize(80, ' ');
    put<uint32_t>(s, count);
    for (const Triangle& t : mesh.triangles) {
        for (int i = 0; i < 3; ++i) put<float>(s, 0.f);
        for (uint32_t v : t)
            for (float x : mesh.positions[v]) put<float>(s, x);
        put<uint16_t>(s, 0);
    }
    return s;
}

const char* kAsciiTetra = R"(solid tetra made by hand
  facet normal 0 0 -1
    outer loop
      vertex 0 0 0
      vertex 0 1 0
      vertex 1 0 0
    endloop
  endfacet
  facet normal 0 -1 0
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 0 0 1
    endloop
  endfacet
  facet normal 1 1 1
    outer loop
      vertex 1 0 0
      vertex 0 1 0
      vertex 0 0 +1.0e0
    endloop
  endfacet
  facet normal -1 0 0
    outer loop
      vertex 0 1 0
      vertex 0 0 0
      vertex 0 0 1
    endloop
  endfacet
endsolid tetra made by hand
)";

}  // namespace

TEST_CASE("mesh_io: format names and extensions") {
    CHECK(meshFormatFromPath("a/b/Bunny.STL") == MeshFormat::Stl);
    CHECK(meshFormatFromPath("x.obj") == MeshFormat::Obj);
    CHECK(meshFormatFromPath("x.ply") == MeshFormat::Ply);
    CHECK(meshFormatFromPath("x.gltf") == MeshFormat::Gltf);
    CHECK(meshFormatFromPath("x.glb") == MeshFormat::Glb);
    CHECK(meshFormatFromName("GLB") == MeshFormat::Glb);
    CHECK(std::string(meshFormatName(MeshFormat::Ply)) == "ply");
    requireError([] { meshFormatFromPath("mesh.xyz"); }, ErrorCode::InvalidInput,
                 {"mesh.xyz", "unknown mesh file extension '.xyz'"});
    requireError([] { meshFormatFromName("3ds"); }, ErrorCode::Usage, {"unknown mesh format '3ds'"});
}

TEST_CASE("mesh_io: binary STL round trip keeps every corner and writes unit facet normals") {
    const TriMesh sphere = makeSphere({1, 2, 3}, 5.0, 8, 16);
    const std::string bytes = serializeMesh(sphere, MeshFormat::Stl);
    REQUIRE(bytes.size() == 84 + 50 * sphere.triangleCount());
    CHECK(bytes.compare(0, 5, "solid") != 0);  // would confuse naive readers
    const TriMesh back = parseMesh(bytes, MeshFormat::Stl, "rt.stl");
    CHECK(sameGeometry(sphere, back));
    CHECK(back.vertexCount() == sphere.vertexCount());  // welded back to shared vertices

    // The stored normal of facet 0 is the unit normal of its corners.
    float n[3];
    std::memcpy(n, bytes.data() + 84, sizeof(n));
    const Vec3f &a = sphere.positions[sphere.triangles[0][0]], &b = sphere.positions[sphere.triangles[0][1]],
                &c = sphere.positions[sphere.triangles[0][2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double e[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    for (int i = 0; i < 3; ++i) CHECK(n[i] == doctest::Approx(e[i] / len).epsilon(1e-6));
    CHECK(std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]) == doctest::Approx(1.0));
}

TEST_CASE("mesh_io: ASCII STL is read and welded; welding can be turned off") {
    const TriMesh welded = parseMesh(kAsciiTetra, MeshFormat::Stl, "tetra.stl");
    CHECK(welded.triangleCount() == 4);
    CHECK(welded.vertexCount() == 4);
    CHECK(signedVolume(welded) == doctest::Approx(1.0 / 6.0));
    MeshReadOptions noWeld;
    noWeld.weldVertices = false;
    const TriMesh raw = parseMesh(kAsciiTetra, MeshFormat::Stl, "tetra.stl", noWeld);
    CHECK(raw.vertexCount() == 12);
    CHECK(sameGeometry(welded, raw));
}

TEST_CASE("mesh_io: STL welding merges -0 with +0 but nothing else") {
    TriMesh m;
    m.positions = {{0.f, 0.f, 0.f},   {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f},
                   {-0.f, 0.f, -0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1e-7f}};
    m.triangles = {{0, 1, 2}, {3, 4, 5}};
    const TriMesh back = parseMesh(binaryStl(m, "x", 2), MeshFormat::Stl, "w.stl");
    CHECK(back.vertexCount() == 4);  // (-0, 0, -0) is the origin; (0, 0, 1e-7) stays apart
    CHECK(back.triangles[1][0] == back.triangles[0][0]);
    CHECK(back.triangles[1][1] == back.triangles[0][2]);
    CHECK(back.triangles[1][2] == 3);
}

TEST_CASE("mesh_io: a binary STL whose header starts with 'solid' is still binary") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 2, 3});
    const std::string bytes =
        binaryStl(box, "solid box exported by a CAD tool", uint32_t(box.triangleCount()));
    const TriMesh back = parseMesh(bytes, MeshFormat::Stl, "cad.stl");
    CHECK(sameGeometry(box, back));
}

TEST_CASE("mesh_io: bad STL input gives one-line errors naming the file") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    requireError([&] { parseMesh(binaryStl(box, "x", 1000), MeshFormat::Stl, "trunc.stl"); },
                 ErrorCode::InvalidInput, {"trunc.stl: truncated binary STL", "1000 triangles"});
    // A "solid" header does not hide the truncation.
    requireError([&] { parseMesh(binaryStl(box, "solid x", 13), MeshFormat::Stl, "trunc2.stl"); },
                 ErrorCode::InvalidInput, {"trunc2.stl: truncated binary STL"});
    requireError([&] { parseMesh(std::string(40, '\0'), MeshFormat::Stl, "short.stl"); },
                 ErrorCode::InvalidInput, {"short.stl: truncated binary STL", "84-byte header"});
    requireError([] { parseMesh("", MeshFormat::Stl, "empty.stl"); }, ErrorCode::InvalidInput,
                 {"empty.stl: empty file"});
    requireError([&] { parseMesh(binaryStl(box, "x", 0).substr(0, 84), MeshFormat::Stl, "none.stl"); },
                 ErrorCode::InvalidInput, {"none.stl: no triangles"});

    TriMesh nan = box;
    nan.positions[5][1] = std::numeric_limits<float>::quiet_NaN();
    requireError([&] { parseMesh(binaryStl(nan, "x", 12), MeshFormat::Stl, "nan.stl"); },
                 ErrorCode::InvalidInput, {"nan.stl: triangle", "non-finite"});
    TriMesh inf = box;
    inf.positions[0][2] = std::numeric_limits<float>::infinity();
    requireError([&] { parseMesh(binaryStl(inf, "x", 12), MeshFormat::Stl, "inf.stl"); },
                 ErrorCode::InvalidInput, {"inf.stl: triangle 0 has a non-finite"});
    std::string asciiInf = kAsciiTetra;
    asciiInf.replace(asciiInf.find("vertex 1 0 0"), 12, "vertex 1 inf 0");
    requireError([&] { parseMesh(asciiInf, MeshFormat::Stl, "inf_ascii.stl"); }, ErrorCode::InvalidInput,
                 {"inf_ascii.stl: line 6", "non-finite"});
    std::string asciiHuge = kAsciiTetra;
    asciiHuge.replace(asciiHuge.find("vertex 1 0 0"), 12, "vertex 1 1e39 0");
    requireError([&] { parseMesh(asciiHuge, MeshFormat::Stl, "huge.stl"); }, ErrorCode::InvalidInput,
                 {"huge.stl: line 6", "out-of-range"});
    std::string asciiBad = kAsciiTetra;
    asciiBad.replace(asciiBad.find("endloop"), 7, "endlop");
    requireError([&] { parseMesh(asciiBad, MeshFormat::Stl, "bad.stl"); }, ErrorCode::InvalidInput,
                 {"bad.stl: line 7: expected 'endloop' but found 'endlop'"});
    requireError([] { parseMesh("hello world, not a mesh", MeshFormat::Stl, "text.stl"); },
                 ErrorCode::InvalidInput, {"text.stl: not an STL file"});
}

TEST_CASE("mesh_io: OBJ round trip is exact") {
    const TriMesh sphere = makeSphere({0.1, -2.5, 1e3}, 0.123456789, 6, 12);
    const TriMesh back = parseMesh(serializeMesh(sphere, MeshFormat::Obj), MeshFormat::Obj, "rt.obj");
    CHECK(back.positions == sphere.positions);
    CHECK(back.triangles == sphere.triangles);
}

TEST_CASE("mesh_io: OBJ polygons, negative indices, v/vt/vn forms, comments and forward references") {
    const std::string obj = R"(# a unit cube as quads
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 -1
f 1/1/1 4/1/1 3/1/1 2/1/1
v 0 0 1   # comment after data
v 1 0 1
v 1 1 1
v 0 1 1 1.0
g top
usemtl red
s off
f -4//1 -3//1 -2//1 -1//1
f 1/1 2/1 6/1 5/1
f 2 3 7 6
f 3 4 8 7
l 1 2
f 4 1 5 8
)";
    const TriMesh m = parseMesh(obj, MeshFormat::Obj, "cube.obj");
    CHECK(m.vertexCount() == 8);
    CHECK(m.triangleCount() == 12);
    CHECK(m.triangles[0] == Triangle{0, 3, 2});  // fan (v0, v1, v2), (v0, v2, v3)
    CHECK(m.triangles[1] == Triangle{0, 2, 1});
    CHECK(m.triangles[2] == Triangle{4, 5, 6});  // -4 is the fifth vertex here
    CHECK(signedVolume(m) == doctest::Approx(1.0));

    const TriMesh forward = parseMesh("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", MeshFormat::Obj, "fwd.obj");
    CHECK(forward.triangleCount() == 1);
    const TriMesh pentagon = parseMesh("v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\r\nf 1 2 3 4 5\r\n",
                                       MeshFormat::Obj, "penta.obj");
    CHECK(pentagon.triangleCount() == 3);
}

TEST_CASE("mesh_io: bad OBJ input names the line") {
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    requireError([&] { parseMesh(v + "f 1 2 3\nf 1 2 9\n", MeshFormat::Obj, "range.obj"); },
                 ErrorCode::InvalidInput,
                 {"range.obj: line 6: vertex index 9 out of range (the file has 4 vertices)"});
    requireError([&] { parseMesh(v + "f 1 0 3\n", MeshFormat::Obj, "zero.obj"); }, ErrorCode::InvalidInput,
                 {"zero.obj: line 5: vertex index 0"});
    requireError([&] { parseMesh(v + "f -1 -2 -5\n", MeshFormat::Obj, "rel.obj"); }, ErrorCode::InvalidInput,
                 {"rel.obj: line 5: relative vertex index -5"});
    requireError([&] { parseMesh(v + "f 1 2\n", MeshFormat::Obj, "short.obj"); }, ErrorCode::InvalidInput,
                 {"short.obj: line 5: face needs at least three vertices"});
    requireError([&] { parseMesh(v + "f 1 2 x\n", MeshFormat::Obj, "x.obj"); }, ErrorCode::InvalidInput,
                 {"x.obj: line 5: bad face vertex 'x'"});
    requireError([&] { parseMesh("v 0 0\n", MeshFormat::Obj, "v.obj"); }, ErrorCode::InvalidInput,
                 {"v.obj: line 1: vertex needs three coordinates"});
    requireError([&] { parseMesh("v 0 nan 0\n", MeshFormat::Obj, "nan.obj"); }, ErrorCode::InvalidInput,
                 {"nan.obj: line 1: non-finite"});
    requireError([&] { parseMesh(v, MeshFormat::Obj, "points.obj"); }, ErrorCode::InvalidInput,
                 {"points.obj: no triangles"});
}

TEST_CASE("mesh_io: binary PLY round trip keeps positions, triangles and salient faces") {
    TriMesh sphere = makeSphere({0, 0, 0}, 2.0, 6, 10);
    CHECK(parseMesh(serializeMesh(sphere, MeshFormat::Ply), MeshFormat::Ply, "rt.ply").positions ==
          sphere.positions);
    sphere.salientFaces.assign(sphere.triangleCount(), 0);
    sphere.salientFaces[3] = sphere.salientFaces[7] = 1;
    const std::string bytes = serializeMesh(sphere, MeshFormat::Ply);
    CHECK(bytes.find("format binary_little_endian 1.0") != std::string::npos);
    const TriMesh back = parseMesh(bytes, MeshFormat::Ply, "rt.ply");
    CHECK(back.positions == sphere.positions);
    CHECK(back.triangles == sphere.triangles);
    CHECK(back.salientFaces == sphere.salientFaces);
}

TEST_CASE("mesh_io: ASCII PLY with extra properties, elements, quads and salient flags") {
    const std::string ply =
        "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info nothing\r\n"
        "element vertex 8\nproperty double x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty uchar red\n"
        "element face 6\nproperty uchar flags\nproperty list uchar uint vertex_indices\n"
        "property int salient\nproperty list int float texcoord\n"
        "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
        "0 0 0 0.5 255\n1 0 0 0 1\n1 1 0 0 1\n0 1 0 0 1\n"
        "0 0 1 0 1\n1 0 1 0 1\n1 1 1 0 1\n0 1 1 0 1\n"
        "7 4 0 3 2 1 1 0\n0 4 4 5 6 7 0 2 0.5 0.5\n0 4 0 1 5 4 0 0\n"
        "0 4 1 2 6 5 0 0\n0 4 2 3 7 6 -2 0\n0 4 3 0 4 7 0 0\n"
        "0 1\n";
    const TriMesh m = parseMesh(ply, MeshFormat::Ply, "cube.ply");
    CHECK(m.vertexCount() == 8);
    CHECK(m.triangleCount() == 12);
    CHECK(signedVolume(m) == doctest::Approx(1.0));
    REQUIRE(m.salientFaces.size() == 12);
    CHECK(m.salientFaces[0] == 1);  // both triangles of the first quad
    CHECK(m.salientFaces[1] == 1);
    CHECK(m.salientFaces[2] == 0);
    CHECK(m.salientFaces[8] == 1);  // salient -2 counts as set
    CHECK(m.salientFaces[9] == 1);
}

TEST_CASE("mesh_io: big-endian binary PLY with double coordinates and short indices") {
    const TriMesh box = makeBox({-1, -2, -3}, {4, 5, 6});
    for (bool big : {true, false}) {
        std::string s = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                        " 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
                        "element face 12\nproperty list ushort short vertex_indices\nend_header\n";
        for (const Vec3f& p : box.positions)
            for (float x : p) put<double>(s, x, big);
        for (const Triangle& t : box.triangles) {
            put<uint16_t>(s, 3, big);
            for (uint32_t v : t) put<int16_t>(s, int16_t(v), big);
        }
        const TriMesh m = parseMesh(s, MeshFormat::Ply, "be.ply");
        CHECK(m.positions == box.positions);
        CHECK(m.triangles == box.triangles);
        // One byte short, one byte too many: both are wrong element counts.
        requireError([&] { parseMesh(s.substr(0, s.size() - 1), MeshFormat::Ply, "short.ply"); },
                     ErrorCode::InvalidInput, {"short.ply: PLY data ends early, in face 11"});
        requireError([&] { parseMesh(s + "x", MeshFormat::Ply, "long.ply"); }, ErrorCode::InvalidInput,
                     {"long.ply: PLY data continues after the last declared element"});
    }
}

TEST_CASE("mesh_io: bad PLY input") {
    const std::string head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
    CHECK(parseMesh(head + verts + "3 0 1 2\n", MeshFormat::Ply, "ok.ply").triangleCount() == 1);
    requireError([&] { parseMesh(head + verts, MeshFormat::Ply, "few.ply"); }, ErrorCode::InvalidInput,
                 {"few.ply: PLY data ends early, in face 0 (element count wrong?)"});
    requireError([&] { parseMesh(head + verts + "3 0 1 2\n3 0 1 2\n", MeshFormat::Ply, "many.ply"); },
                 ErrorCode::InvalidInput, {"many.ply: PLY data continues after the last declared element"});
    requireError([&] { parseMesh(head + verts + "3 0 1 3\n", MeshFormat::Ply, "idx.ply"); },
                 ErrorCode::InvalidInput, {"idx.ply: face 0 refers to vertex 3 but there are 3 vertices"});
    requireError([&] { parseMesh(head + verts + "3 0 -1 2\n", MeshFormat::Ply, "neg.ply"); },
                 ErrorCode::InvalidInput, {"neg.ply: face 0 refers to vertex -1"});
    requireError([&] { parseMesh(head + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Ply, "nan.ply"); },
                 ErrorCode::InvalidInput, {"nan.ply: vertex 1 has a non-finite coordinate"});
    requireError([&] { parseMesh("solid x\n", MeshFormat::Ply, "stl.ply"); }, ErrorCode::InvalidInput,
                 {"stl.ply: not a PLY file"});
    requireError(
        [&] { parseMesh("ply\nformat ascii 1.0\nelement vertex 3\n", MeshFormat::Ply, "nohead.ply"); },
        ErrorCode::InvalidInput, {"nohead.ply: PLY header has no 'end_header'"});
    requireError(
        [&] {
            parseMesh(
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float "
                "z\n"
                "end_header\n0 0 0\n",
                MeshFormat::Ply, "cloud.ply");
        },
        ErrorCode::InvalidInput, {"cloud.ply: PLY has no 'face' element"});
}

TEST_CASE("mesh_io: readMesh reports missing files, directories and unknown extensions") {
    ScratchDir dir;
    requireError([&] { readMesh(dir.file("missing.stl")); }, ErrorCode::InvalidInput,
                 {"missing.stl: no such file"});
    requireError([&] { readMesh(dir.path().string()); }, ErrorCode::InvalidInput, {"is a directory"});
    writeBytes(dir.file("tetra.xyz"), kAsciiTetra);
    requireError([&] { readMesh(dir.file("tetra.xyz")); }, ErrorCode::InvalidInput,
                 {"tetra.xyz: unknown mesh file extension '.xyz'"});
    MeshReadOptions asStl;
    asStl.format = MeshFormat::Stl;
    CHECK(readMesh(dir.file("tetra.xyz"), asStl).triangleCount() == 4);  // an explicit format wins
    writeBytes(dir.file("empty.ply"), "");
    requireError([&] { readMesh(dir.file("empty.ply")); }, ErrorCode::InvalidInput,
                 {"empty.ply: empty file"});
    requireError([&] { readMesh("-"); }, ErrorCode::Usage, {"--in-format"});
}

TEST_CASE("mesh_io: writeMesh writes every format atomically and refuses what it cannot write") {
    ScratchDir dir;
    const TriMesh box = makeBox({0, 0, 0}, {10, 20, 30});
    for (const char* name : {"box.stl", "box.obj", "box.ply"}) {
        writeMesh(box, dir.file(name));
        const TriMesh back = readMesh(dir.file(name));
        CHECK(sameGeometry(box, back));
    }
    MeshWriteOptions asPly;
    asPly.format = MeshFormat::Ply;
    writeMesh(box, dir.file("box.bin"), asPly);
    MeshReadOptions readPly;
    readPly.format = MeshFormat::Ply;
    CHECK(readMesh(dir.file("box.bin"), readPly).triangleCount() == 12);

    requireError([&] { writeMesh(box, dir.file("box.glb")); }, ErrorCode::Usage,
                 {"box.glb", "cannot write meshes as glb"});
    requireError([&] { writeMesh(box, dir.file("box.xyz")); }, ErrorCode::Usage,
                 {"unknown mesh output extension"});
    requireError([&] { writeMesh(box, "-"); }, ErrorCode::Usage, {"--out-format"});
    requireError([&] { writeMesh(box, dir.file("no/such/dir/box.stl")); }, ErrorCode::WriteFailed,
                 {"box.stl"});
    TriMesh broken = box;
    broken.triangles[0][0] = 99;
    requireError([&] { writeMesh(broken, dir.file("broken.stl")); }, ErrorCode::Internal, {"vertex 99"});
    CHECK(!std::filesystem::exists(dir.file("box.glb")));
    CHECK(!std::filesystem::exists(dir.file("broken.stl")));
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
        files += entry.is_regular_file();
    CHECK(files == 4);  // no temporaries left behind
}

TEST_CASE("mesh_io: the bundled sample meshes read as closed binary STL") {
    const TriMesh bunny = readMesh(dataPath("bunny_npm_3674.stl"));
    CHECK(bunny.triangleCount() == 3674);
    CHECK(bunny.vertexCount() == 1839);
}

// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/sdf/vdb_file.h"

#include <doctest/doctest.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "test_util.h"
#include "vdb_test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/sdf/level_set_grid.h"

using namespace zomefab;
using namespace zomefab::sdf;

namespace {

ErrorCode parseCode(const std::string& bytes) {
    try {
        parseVdb(bytes, "in.vdb", RunContext::silent());
    } catch (const Error& e) {
        CHECK(std::string(e.what()).rfind("in.vdb: ", 0) == 0);  // names the file
        return e.code();
    }
    FAIL("no error");
    return ErrorCode::Internal;
}

/// A .vdb written by plain OpenVDB (no zomefab metadata).
std::string foreignVdb(openvdb::GridBase::Ptr grid) {
    openvdb::initialize();
    std::ostringstream out;
    openvdb::io::Stream(out).write({grid});
    return out.str();
}

}  // namespace

TEST_CASE("vdb_file: metadata and values survive a round trip, and bytes are deterministic") {
    LevelSet object = meshToLevelSet(test::makeSphere({0, 0, 10}, 12.0), {}, RunContext::silent());
    object.info().sourceFile = "some dir/bunny.stl";
    object.info().generator = "zomefab 9.9.9";
    object.info().transformMm = Transform4d::scaleTranslate(2.5, {1, -2, 3}) * Transform4d::yUpToZUp();
    object.info().interiorBandMm = 7.5;
    MeshToLevelSetOptions coarse;
    coarse.voxelMm = 2.0;
    coarse.interiorBandMm = std::numeric_limits<double>::infinity();
    coarse.name = "interior";
    const LevelSet interior =
        meshToLevelSet(test::makeSphere({0, 0, 10}, 12.0), coarse, RunContext::silent());

    const std::string bytes = serializeVdb({object, interior});
    CHECK(bytes == serializeVdb({object, interior}));  // no random UUID

    RunContext context;
    const std::vector<LevelSet> back = parseVdb(bytes, "x.vdb", context);
    CHECK(context.warnings().empty());
    REQUIRE(back.size() == 2);
    const LevelSetInfo& a = back[0].info();
    CHECK(a.name == "object");
    CHECK(a.voxelMm == 1.0);
    CHECK(a.sourceFile == "some dir/bunny.stl");
    CHECK(a.generator == "zomefab 9.9.9");
    CHECK(a.interiorBandMm == 7.5);
    CHECK(a.exteriorBandMm == 0.0);
    CHECK(a.transformMm == object.info().transformMm);
    CHECK(back[0].activeVoxelCount() == object.activeVoxelCount());
    CHECK(back[0].valueMm({3.3, 1.1, 14.0}) == object.valueMm({3.3, 1.1, 14.0}));
    CHECK(back[1].info().name == "interior");
    CHECK(std::isinf(back[1].info().interiorBandMm));
    CHECK(&findLevelSet(back, "interior", "x.vdb") == &back[1]);
    CHECK(&findLevelSet(back, "", "x.vdb") == &back[0]);
    try {
        findLevelSet(back, "shell", "x.vdb");
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
        CHECK(std::string(e.what()).find("'object', 'interior'") != std::string::npos);
    }
}

TEST_CASE("vdb_file: what is not a millimetre level set is rejected with InvalidInput") {
    CHECK(parseCode("") == ErrorCode::InvalidInput);
    CHECK(parseCode("solid cube\nendsolid cube\n") == ErrorCode::InvalidInput);
    const std::string good =
        serializeVdb({meshToLevelSet(test::makeSphere({0, 0, 0}, 5.0), {}, RunContext::silent())});
    CHECK(parseCode(good.substr(0, good.size() / 2)) == ErrorCode::InvalidInput);  // truncated

    // A fog volume is not a level set.
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
    fog->setName("density");
    fog->setGridClass(openvdb::GRID_FOG_VOLUME);
    fog->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
    CHECK(parseCode(foreignVdb(fog)) == ErrorCode::InvalidInput);

    // A level set in inches.
    openvdb::FloatGrid::Ptr inches =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(5.0f, {0, 0, 0}, 0.5f);
    inches->setName("object");
    inches->insertMeta("units", openvdb::StringMetadata("inch"));
    CHECK(parseCode(foreignVdb(inches)) == ErrorCode::InvalidInput);
}

TEST_CASE("vdb_file: a foreign level set without metadata is read as millimetres with a warning") {
    openvdb::FloatGrid::Ptr sphere =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(10.0f, {0, 0, 0}, 0.5f);
    sphere->setName("ball");
    RunContext context;
    const std::vector<LevelSet> grids = parseVdb(foreignVdb(sphere), "ball.vdb", context);
    REQUIRE(grids.size() == 1);
    CHECK(grids[0].info().name == "ball");
    CHECK(grids[0].info().voxelMm == 0.5);
    CHECK(grids[0].info().transformMm == Transform4d::identity());
    CHECK(context.warnings().size() == 1);
    CHECK(std::abs(grids[0].valueMm({10, 0, 0})) < 0.05);
}

// ---- damaged and hostile streams (vdb_check.cpp) ----------------------------------------------

namespace {

/// A small zomefab file: a 6 mm sphere at 1 mm voxels, a few kilobytes.
std::string smallZomefabVdb() {
    return serializeVdb({meshToLevelSet(test::makeSphere({0, 0, 0}, 6.0), {}, RunContext::silent())});
}

/// parseVdb's error for @p bytes; empty when it succeeded. Anything but a zomefab::Error fails.
std::string parseError(const std::string& bytes) {
    try {
        parseVdb(bytes, "in.vdb", RunContext::silent());
    } catch (const Error& e) {
        return e.code() == ErrorCode::InvalidInput ? std::string(e.what())
                                                   : "wrong code: " + std::string(e.what());
    }
    return {};
}

}  // namespace

TEST_CASE("vdb_file: a zomefab file carries its checksum, and any flipped bit is a one-line InvalidInput") {
    const std::string good = smallZomefabVdb();
    CHECK(good.compare(test::kVdbUuidAt, 9, "7a6f6d65-") == 0);  // the UUID mark
    CHECK(parseError(good).empty());
    // Every byte, one bit each (the bit changes with the position): header, metadata, topology,
    // compressed values.
    size_t failures = 0;
    for (size_t i = 0; i < good.size(); ++i) {
        std::string bad = good;
        bad[i] = char(bad[i] ^ (1 << (i % 8)));
        const std::string error = parseError(bad);
        failures += error.empty() ? 0 : 1;
        if (error.empty() || error.find('\n') != std::string::npos || error.rfind("in.vdb: ", 0) != 0) {
            FAIL_CHECK("byte " << i << ": " << (error.empty() ? "accepted" : error));
            break;
        }
    }
    CHECK(failures == good.size());
    // Two bits at 5 %, 25 % and 75 %: the checksum, not the walk, finds them.
    for (double at : {0.05, 0.25, 0.75}) {
        std::string bad = good;
        const size_t i = size_t(at * double(good.size()));
        bad[i] = char(bad[i] ^ 0x11);
        CHECK(parseError(bad).find("checksum does not match") != std::string::npos);
    }
}

TEST_CASE("vdb_file: lengths and counts are checked before OpenVDB trusts them") {
    const std::string foreign = test::withoutVdbChecksum(smallZomefabVdb());
    RunContext context;
    REQUIRE(parseVdb(foreign, "in.vdb", context).size() == 1);  // still readable without the checksum
    const size_t gridName = test::kVdbGridNameAt;               // file metadata count, grid count
    CHECK(parseError(test::withU32(foreign, gridName, 0xfffffff0u))
              .find("a grid name announces 4294967280 bytes") != std::string::npos);
    const size_t gridMetaSize = foreign.find("class") + 5 + 4 + 6;  // the first entry's size field
    CHECK(parseError(test::withU32(foreign, gridMetaSize, 0x7fffffffu))
              .find("truncated .vdb stream: a metadata value") != std::string::npos);
    CHECK(parseError(test::withU32(foreign, test::kVdbFileMetaAt, 0x40000000u))
              .find("the file metadata announces") != std::string::npos);
    CHECK(parseError(test::withU32(foreign, test::kVdbFileMetaAt + 4, 0x7fffffffu)).find("grid count") !=
          std::string::npos);
    CHECK(parseError(foreign.substr(0, 40)).find("truncated .vdb stream: the archive UUID") !=
          std::string::npos);
    CHECK(parseError(foreign.substr(0, 6)).find("not a .vdb file") != std::string::npos);
    CHECK(parseError(foreign.substr(0, foreign.size() - 1)).find("truncated") != std::string::npos);
    CHECK(parseError(foreign + "x").find("1 bytes after the last grid") != std::string::npos);
    // Another file version, a map OpenVDB knows but zomefab does not take.
    CHECK(parseError(test::withU32(foreign, 8, 300)).find("file format version 300") != std::string::npos);
    std::string affine = foreign;
    const size_t map = affine.find("UniformScaleMap");
    REQUIRE(map != std::string::npos);
    affine.replace(map, 15, "UniformScaleMaq");
    CHECK(parseError(affine).find("UniformScaleMaq transform; only uniform voxels") != std::string::npos);
}

TEST_CASE("vdb_file: random damage to a file without checksum is an error or a level set, never a crash") {
    // Each case either parses (the damage hit voxel values) or is one InvalidInput line; the
    // sanitizer build (make fuzz, fuzz_vdb) runs the same over millions of inputs.
    const std::string foreign = test::withoutVdbChecksum(smallZomefabVdb());
    uint64_t state = 12345;
    auto next = [&state] { return state = state * 6364136223846793005ull + 1442695040888963407ull; };
    int refused = 0, read = 0;
    for (int trial = 0; trial < 400; ++trial) {
        std::string bad = foreign;
        for (int k = 0; k < 1 + trial % 3; ++k) {
            const size_t i = size_t(next() >> 33) % bad.size();
            bad[i] = char(bad[i] ^ (1 << (next() >> 61)));
        }
        const std::string error = parseError(bad);
        CHECK(error.find("wrong code") == std::string::npos);
        (error.empty() ? read : refused) += 1;
    }
    CHECK(refused > 0);
    MESSAGE(read << " damaged files read, " << refused << " refused");
}

TEST_CASE("vdb_file: instanced and half-float grids of other programs, and other grid types") {
    openvdb::initialize();
    openvdb::FloatGrid::Ptr sphere =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(6.0f, {0, 0, 0}, 0.5f);
    sphere->setName("ball");
    sphere->insertMeta("units", openvdb::StringMetadata("mm"));
    openvdb::FloatGrid::Ptr copy = sphere->copy();  // shares the tree: written as an instance
    copy->setName("twin");
    {
        const auto grids = parseVdb(foreignVdb(sphere), "in.vdb", RunContext::silent());
        REQUIRE(grids.size() == 1);
    }
    std::ostringstream both;
    openvdb::io::Stream(both).write({sphere, copy});
    const auto twins = parseVdb(both.str(), "in.vdb", RunContext::silent());
    REQUIRE(twins.size() == 2);
    CHECK(twins[1].info().name == "twin");
    CHECK(twins[1].activeVoxelCount() == twins[0].activeVoxelCount());

    openvdb::FloatGrid::Ptr half = sphere->deepCopy();
    half->setSaveFloatAsHalf(true);
    const auto halves = parseVdb(foreignVdb(half), "in.vdb", RunContext::silent());
    REQUIRE(halves.size() == 1);
    CHECK(std::abs(halves[0].valueMm({6, 0, 0})) < 0.05);

    // A vector grid in a stream (no offsets) cannot be stepped over.
    openvdb::Vec3SGrid::Ptr velocity = openvdb::Vec3SGrid::create();
    velocity->setName("v");
    velocity->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 2, 3));
    std::ostringstream mixed;
    openvdb::io::Stream(mixed).write({velocity, sphere});
    CHECK(parseError(mixed.str()).find("grid 'v' of type Tree_vec3s_5_4_3 cannot be skipped") !=
          std::string::npos);
    // A file written by io::File has offsets: the vector grid is skipped.
    test::ScratchDir dir("zomefab-vdb-file");
    openvdb::io::File file(dir.file("mixed.vdb"));
    file.write({velocity, sphere});
    file.close();
    const auto found = parseVdb(test::readFile(dir.file("mixed.vdb")), "mixed.vdb", RunContext::silent());
    REQUIRE(found.size() == 1);
    CHECK(found[0].info().name == "ball");
}

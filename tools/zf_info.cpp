// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-info: read meshes, check them as stage 1 would, print a JSON report per mesh on stdout
/// and one size line per mesh on stderr. A mesh that fails validation (open, non-manifold, zero
/// volume, ...) fails the run with exit code 2 and writes nothing, unless --allow-invalid
/// (docs/cli.md).
#include <cstdio>

#include "common/cli.h"
#include "common/scale_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/version.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"

using namespace zomefab;
using nlohmann::json;

namespace {

json vec(const Vec3d& v) { return json::array({v[0], v[1], v[2]}); }

/// @p mm: the mesh is in millimetres, so the keys carry units; otherwise it is in file units.
json reportJson(const mesh::MeshReport& r, bool mm) {
    const std::string len = mm ? "_mm" : "";
    json j;
    j["vertices"] = r.vertexCount;
    j["triangles"] = r.triangleCount;
    if (!r.bounds.isEmpty())
        j["bbox" + len] = {
            {"min", vec(r.bounds.min)}, {"max", vec(r.bounds.max)}, {"size", vec(r.bounds.size())}};
    j[mm ? "volume_mm3" : "volume"] = r.volume;
    j[mm ? "area_mm2" : "area"] = r.area;
    j["closed"] = r.isClosed();
    j["consistently_oriented"] = r.isConsistentlyOriented();
    j["components"] = r.components;
    j["boundary_edges"] = r.boundaryEdges;
    j["boundary_loops"] = r.boundaryLoops;
    if (!r.boundaryBounds.isEmpty())
        j["boundary_bbox" + len] = {{"min", vec(r.boundaryBounds.min)}, {"max", vec(r.boundaryBounds.max)}};
    j["non_manifold_edges"] = r.nonManifoldEdges;
    j["inconsistent_edges"] = r.inconsistentEdges;
    j["degenerate_triangles"] = r.degenerateTriangles;
    j["duplicate_triangles"] = r.duplicateTriangles;
    j["non_finite_vertices"] = r.nonFiniteVertices;
    j["unreferenced_vertices"] = r.unreferencedVertices;
    return j;
}

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zf-info",
                   "Check meshes as the pipeline's first stage does and print a JSON report for each.");
    std::vector<std::string> inputs;
    std::string inFormat;
    cli::ScaleCli scaleCli;
    bool allowInvalid = false;
    mesh::ValidateOptions validateOptions;
    auto& app = tool.app();
    app.add_option("meshes", inputs, "Mesh files (.stl .obj .ply .gltf .glb); - reads stdin")->required();
    scaleCli.addTo(app);
    tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"},
                         "Input format (needed for -)");
    app.add_flag("--repair", validateOptions.repair, "Fill holes of up to 300 edges (minimum-area patches)");
    app.add_flag("--allow-invalid", allowInvalid,
                 "Report meshes that fail validation (\"valid\": false and the error) instead of failing");

    return tool.run(argc, argv, [&](json& report) {
        const mesh::ScaleOptions scaleOptions =
            scaleCli.resolve();  // bad options fail before any input is read
        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        report = {{"format", "zomefab.info"},
                  {"version", 1},
                  {"generator", generatorString()},
                  {"meshes", json::array()}};
        std::vector<std::string> sizeLines;
        for (const std::string& path : inputs) {
            tool.context().throwIfCancelled();
            const TriMesh input = readMesh(path, readOptions);
            json entry = {{"file", path},
                          {"format", meshFormatName(readOptions.format ? *readOptions.format
                                                                       : meshFormatFromPath(path))},
                          {"input", reportJson(mesh::checkMesh(input), false)}};
            try {
                TriMesh valid = mesh::validateClosedMesh(input, validateOptions, path, tool.context());
                mesh::ScaledMesh scaled = mesh::scaleToMillimetres(std::move(valid), scaleOptions);
                const mesh::MeshReport r = mesh::checkMesh(scaled.mesh);
                entry["valid"] = true;
                entry["mesh"] = reportJson(r, true);
                json t = json::array();
                for (int row = 0; row < 4; ++row)
                    t.push_back({scaled.transformMm.at(row, 0), scaled.transformMm.at(row, 1),
                                 scaled.transformMm.at(row, 2), scaled.transformMm.at(row, 3)});
                entry["transform_mm"] = t;
                char line[256];
                std::snprintf(line, sizeof(line),
                              "%s: %zu triangles, %zu vertices, %.1f x %.1f x %.1f mm, volume %.4g mm^3, %zu "
                              "component%s",
                              path.c_str(), r.triangleCount, r.vertexCount, scaled.sizeMm[0],
                              scaled.sizeMm[1], scaled.sizeMm[2], r.volume, r.components,
                              r.components == 1 ? "" : "s");
                sizeLines.push_back(line);
            } catch (const Error& e) {
                if (!allowInvalid || e.code() != ErrorCode::InvalidInput) throw;
                entry["valid"] = false;
                entry["error"] = e.message();
                sizeLines.push_back(path + ": invalid: " + e.message());
            }
            report["meshes"].push_back(std::move(entry));
        }
        std::printf("%s\n", report.dump(2).c_str());
        for (const std::string& line : sizeLines) cli::printInfo(tool, line);
        return 0;
    });
}

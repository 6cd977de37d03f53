// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-preview: the preview.glb of `zomefab run` from separate files, for pipelines. Reads a
/// frame file and, optionally, the pieces (pieces.json of zf-pieces, or a directory of meshes),
/// builds the scene (lib/zomefab/report/preview_scene.h) and writes it. docs/preview.md.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/report/run_report.h"
#include "zomefab/report/viewer_page.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

/// A directory of meshes already in frame mm (no pieces.json): one piece per file, sorted.
void readMeshDirectory(const std::string& path, std::vector<TriMesh>& meshes,
                       std::vector<std::string>& names) {
    std::error_code ec;
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
        const std::string ext = fileExtension(e.path().string());
        if (e.is_regular_file() &&
            (ext == "stl" || ext == "obj" || ext == "ply" || ext == "glb" || ext == "gltf"))
            files.push_back(e.path());
    }
    if (ec) throw Error(ErrorCode::InvalidInput, "cannot list the directory: " + ec.message(), path);
    if (files.empty())
        throw Error(ErrorCode::InvalidInput, "no pieces.json and no mesh files in the directory", path);
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files)
        meshes.push_back(readMesh(f.string())), names.push_back(f.stem().string());
}

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zf-preview", "Write the preview.glb of a frame and, optionally, its printed pieces");
    CLI::App& app = tool.app();
    std::string framePath, piecesPath, objectPath, output, viewer;
    cli::ScaleCli scaleCli;
    cli::PreviewCli previewCli;
    app.add_option("frame", framePath, "Frame file (zomefab.structure JSON, - = stdin)")->required();
    app.add_option("--pieces", piecesPath,
                   "pieces.json of zf-pieces, a directory holding one, or a directory of meshes in frame mm");
    app.add_option("--object", objectPath,
                   "The input mesh, to name it and its size in the scene (with --height-mm, --up)");
    app.add_option("-o,--output", output, "Output .glb (- = stdout)")->required();
    app.add_option("--viewer", viewer, "Also write this viewer.html: the scene in a page that opens offline");
    scaleCli.addTo(app);
    previewCli.addTo(app);

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        const report::PreviewOptions options = previewCli.resolve();
        const mesh::ScaleOptions scale = scaleCli.resolve();
        const zome::Structure frame = cli::readFrame(framePath);
        report::PreviewInput input;
        input.frame = &frame;
        pieces::Pieces pieces;
        std::vector<TriMesh> meshes;
        std::error_code ec;
        if (!piecesPath.empty() &&
            (!fs::is_directory(piecesPath, ec) || fs::exists(fs::path(piecesPath) / pieces::kPiecesFile))) {
            pieces = pieces::readPieces(piecesPath);
            input = report::previewInput(pieces, frame);
        } else if (!piecesPath.empty()) {
            readMeshDirectory(piecesPath, meshes, input.pieceNames);
            for (const TriMesh& m : meshes) input.pieces.push_back(&m);
        }
        input.extras = {{"frame_file", framePath}};
        if (!objectPath.empty())
            input.extras = report::previewExtras(
                objectPath,
                mesh::scaleToMillimetres(
                    mesh::validateClosedMesh(readMesh(objectPath), {}, objectPath, tool.context()), scale)
                    .sizeMm);
        const std::string glb = serializeGlb(report::buildPreviewScene(input, options), options.glb);
        if (!viewer.empty()) report::writeViewer(input, options, viewer);  // first: a failure leaves no GLB
        tool.writeOutput(output,
                         [&](std::ostream& out) { out.write(glb.data(), std::streamsize(glb.size())); });

        report = {{"frame", framePath},         {"pieces", input.pieces.size()},
                  {"balls", frame.ballCount()}, {"struts", frame.strutCount()},
                  {"output", output},           {"bytes", glb.size()}};
        if (!viewer.empty()) report["viewer"] = viewer;
        cli::printInfo(tool, framePath + ": " + std::to_string(frame.ballCount()) + " balls, " +
                                 std::to_string(frame.strutCount()) + " struts, " +
                                 std::to_string(input.pieces.size()) + " pieces -> " + output +
                                 formatNumbers(" (%.1f kB)", double(glb.size()) / 1000.0));
        return 0;
    });
}

// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-preview: the preview.glb of `zomefab run` from separate files, for pipelines. Reads a
/// frame file and, optionally, the pieces (pieces.json of zf-pieces, or a directory of meshes),
/// builds the scene (lib/zomefab/report/preview_scene.h) and writes it. docs/preview.md.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/cli.h"
#include "zomefab/core/error.h"
#include "zomefab/core/transform.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/report/preview_scene.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

struct LoadedPieces {
    std::vector<TriMesh> meshes;
    std::vector<std::string> names;
    std::vector<Transform4d> toFrame;  ///< printer → frame mm, one per piece
};

Transform4d matrixFrom(const nlohmann::json& rows, const std::string& file, const std::string& what) {
    Transform4d t;
    if (!rows.is_array() || rows.size() != 4)
        throw Error(ErrorCode::InvalidInput, what + " is not a 4x4 matrix", file);
    for (int r = 0; r < 4; ++r) {
        const nlohmann::json& row = rows[size_t(r)];
        if (!row.is_array() || row.size() != 4)
            throw Error(ErrorCode::InvalidInput, what + " is not a 4x4 matrix", file);
        for (int c = 0; c < 4; ++c) {
            if (!row[size_t(c)].is_number())
                throw Error(ErrorCode::InvalidInput, what + " has a non-number", file);
            t.m[size_t(r * 4 + c)] = row[size_t(c)].get<double>();
        }
    }
    return t;
}

/// pieces.json (zomefab.pieces v1): each piece's STL is in printer coordinates; the inverse of its
/// orientation.transform_mm takes it to the shell grid, the inverse of frame_to_grid_mm to the frame.
LoadedPieces readPiecesJson(const std::string& path) {
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(readInputBytes(path));
    } catch (const nlohmann::json::exception& e) {
        throw Error(ErrorCode::InvalidInput, std::string("invalid JSON: ") + e.what(), path);
    }
    if (!j.is_object() || j.value("format", "") != "zomefab.pieces")
        throw Error(ErrorCode::InvalidInput, "not a pieces file (format zomefab.pieces)", path);
    if (j.value("version", 0) != 1)
        throw Error(ErrorCode::InvalidInput,
                    "unsupported version " + j.value("version", nlohmann::json()).dump(), path);
    if (!j.contains("pieces") || !j["pieces"].is_array())
        throw Error(ErrorCode::InvalidInput, "no pieces array", path);
    const Transform4d gridToFrame =
        j.contains("frame_to_grid_mm")
            ? affineInverse(matrixFrom(j["frame_to_grid_mm"], path, "frame_to_grid_mm"))
            : Transform4d::identity();
    const fs::path dir = fs::path(path).parent_path();
    LoadedPieces out;
    for (size_t i = 0; i < j["pieces"].size(); ++i) {
        const nlohmann::json& p = j["pieces"][i];
        const std::string what = "pieces[" + std::to_string(i) + "]";
        if (!p.is_object() || !p.contains("file") || !p["file"].is_string())
            throw Error(ErrorCode::InvalidInput, what + " has no file", path);
        const fs::path file = dir / p["file"].get<std::string>();
        out.meshes.push_back(readMesh(file.string()));
        if (p.contains("orientation") && p["orientation"].contains("transform_mm"))
            out.toFrame.push_back(gridToFrame *
                                  affineInverse(matrixFrom(p["orientation"]["transform_mm"], path,
                                                           what + ".orientation.transform_mm")));
        else
            out.toFrame.push_back(gridToFrame);
        out.names.push_back(file.stem().string());
    }
    return out;
}

/// --pieces: pieces.json, a directory holding one, or a directory of meshes already in frame mm.
LoadedPieces readPieces(const std::string& path) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) return readPiecesJson(path);
    if (fs::exists(fs::path(path) / "pieces.json"))
        return readPiecesJson((fs::path(path) / "pieces.json").string());
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
    LoadedPieces out;
    for (const fs::path& f : files) {
        out.meshes.push_back(readMesh(f.string()));
        out.names.push_back(f.stem().string());
        out.toFrame.push_back(Transform4d::identity());
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zf-preview", "Write the preview.glb of a frame and, optionally, its printed pieces");
    CLI::App& app = tool.app();
    std::string framePath, piecesPath, output;
    bool noDraco = false;
    report::PreviewOptions options;
    app.add_option("frame", framePath, "Frame file (zomefab.structure JSON, - = stdin)")->required();
    app.add_option("--pieces", piecesPath,
                   "pieces.json of zf-pieces, a directory holding one, or a directory of meshes in frame mm");
    app.add_option("-o,--output", output, "Output .glb (- = stdout)")->required();
    app.add_flag("--no-draco", noDraco, "Store the pieces uncompressed (no KHR_draco_mesh_compression)");
    app.add_option("--draco-bits", options.glb.dracoPositionBits, "Draco position quantisation, bits")
        ->capture_default_str()
        ->check(CLI::Range(8, 30));

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        const Stopwatch clock;
        zome::Structure frame;
        try {
            frame = zome::structureFromJsonText(readInputBytes(framePath));
        } catch (const Error& e) {
            throw e.withFile(framePath);
        }
        LoadedPieces pieces;
        if (!piecesPath.empty()) pieces = readPieces(piecesPath);
        options.isPieceDracoCompressed = !noDraco;

        report::PreviewInput input;
        input.pieces = std::move(pieces.meshes);
        input.pieceNames = std::move(pieces.names);
        input.pieceTransforms = std::move(pieces.toFrame);
        input.frame = &frame;
        input.extras = {{"frame_file", framePath}};
        const std::string glb = serializeGlb(report::buildPreviewScene(input, options), options.glb);
        writeOutputAtomic(output,
                          [&](std::ostream& out) { out.write(glb.data(), std::streamsize(glb.size())); });

        report["frame"] = framePath;
        report["pieces"] = input.pieces.size();
        report["balls"] = frame.ballCount();
        report["struts"] = frame.strutCount();
        report["output"] = output;
        report["bytes"] = glb.size();
        report["seconds"] = clock.seconds();
        char size[64];
        std::snprintf(size, sizeof size, "%.1f kB", double(glb.size()) / 1000.0);
        cli::printInfo(tool, framePath + ": " + std::to_string(frame.ballCount()) + " balls, " +
                                 std::to_string(frame.strutCount()) + " struts, " +
                                 std::to_string(input.pieces.size()) + " pieces -> " + output + " (" + size +
                                 ")");
        return 0;
    });
}

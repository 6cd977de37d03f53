// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Every option of every stage, declared once: each stage tool adds its stage's group, and
/// `zomefab run` (so also a batch manifest, docs/batch.md) adds them all, with the same names, help
/// and defaults. A group holds the stage's options struct plus the texts that can only be turned
/// into values after parsing (a printer size, a salient sphere); resolve() does that and checks.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "scale_options.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/frame/frame.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/partition/partition.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/report/cost_report.h"
#include "zomefab/report/preview_scene.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::cli {

/// "200x200x200" or "200,200,200" (mm). @throw Error(Usage) naming --printer-mm
Vec3d parsePrinterMm(const std::string& text);
/// "x,y,z,r" (mm). @throw Error(Usage) naming --salient
partition::SalientSphere parseSalientSphere(const std::string& text);
/// A JSON list of face indices, or {"salient_faces": [...]}, every index below @p faceCount.
/// @throw Error(InvalidInput) naming @p path
std::vector<uint32_t> readSalientFaceList(const std::string& path, size_t faceCount);

/// A frame file (zomefab.structure JSON) and its transform_mm. @throw Error(InvalidInput) naming @p path
zome::Structure readFrame(const std::string& path, Transform4d* transformMm = nullptr,
                          const zome::ZomeScale& physical = {}, const zome::CollisionOptions& collision = {});

/// A partition file (zomefab.partition JSON). @throw Error(InvalidInput) naming @p path
partition::PartitionFile readPartition(const std::string& path);

/// Which parts of the Fabrication a tool takes on its command line.
enum FabricationPart : unsigned {
    kPrinter = 1u << 0,         ///< --printer-mm, --fit-margin-mm, --bed-margin-mm
    kWall = 1u << 1,            ///< --shell-mm
    kFrameClearance = 1u << 2,  ///< --frame-clearance-mm, --b0-mm
    kAllFabrication = kPrinter | kWall | kFrameClearance,
};

struct FabricationCli {
    Fabrication fabrication;
    std::string printer;  ///< --printer-mm as given; empty = the default (or, for zf-pieces, the partition's)
    CLI::Option* wallOption = nullptr;  ///< --shell-mm, where the tool has it

    void addTo(CLI::App& app, unsigned parts);
    /// Whether --shell-mm was given (a wall the user chose is printed as it is).
    bool isWallGiven() const { return wallOption && wallOption->count() > 0; }
    /// The Fabrication with --printer-mm parsed and @p seed (the tool's --seed) filled in.
    /// @throw Error(Usage) naming the option.
    Fabrication resolve(uint64_t seed) const;
};

struct ValidateCli {
    mesh::ValidateOptions options;
    void addTo(CLI::App& app);
};

struct FieldCli {
    sdf::ObjectFieldOptions options;
    void addTo(CLI::App& app);
};

struct FrameCli {
    frame::FrameOptions options;
    void addTo(CLI::App& app);
};

struct PartitionCli {
    partition::PartitionOptions options;
    std::vector<std::string> salientSpheres;  ///< --salient, parsed by resolve()
    std::string salientFacesFile;             ///< --salient-faces, read by resolveSalientFaces()
    bool isOneVsRest = false;

    void addTo(CLI::App& app);
    /// The options with the spheres parsed. @throw Error(Usage)
    partition::PartitionOptions resolve() const;
    /// Reads --salient-faces (if given) for a mesh of @p faceCount faces. @throw Error(InvalidInput)
    void resolveSalientFaces(partition::PartitionOptions& options, size_t faceCount) const;
};

struct PiecesCli {
    pieces::PiecesOptions options;
    bool isUnlabelled = false;
    bool isNotGluing = false;  ///< --no-glue-groups
    std::string tenonHoles = "all";
    std::string printWall = "auto";  ///< --print-wall-mm as given

    void addTo(CLI::App& app);
    /// @p isWallGiven: the user chose the shell's wall (zomefab run --shell-mm), so "auto" prints it.
    /// @throw Error(Usage) for an option out of its range.
    pieces::PiecesOptions resolve(bool isWallGiven = false) const;
};

struct CostCli {
    report::CostOptions options;
    std::string slicer = "estimator";

    void addTo(CLI::App& app);
    /// @throw Error(Usage), also when --slicer prusa-slicer is not installed.
    report::CostOptions resolve() const;
};

struct PreviewCli {
    report::PreviewOptions options;
    bool isUncompressed = false;

    void addTo(CLI::App& app);
    report::PreviewOptions resolve() const;
};

}  // namespace zomefab::cli

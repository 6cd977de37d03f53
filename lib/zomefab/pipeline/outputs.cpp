// SPDX-License-Identifier: GPL-3.0-or-later
// The writers of a run's output directory: each file comes from the writer its stage tool uses.
#include <algorithm>
#include <filesystem>
#include <functional>

#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/pipeline/pipeline.h"
#include "zomefab/report/run_report.h"
#include "zomefab/report/viewer_page.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::pipeline {

namespace {

/// OUT.failed for OUT (a trailing slash dropped).
std::string failedDirectory(const std::string& outDir) {
    std::string base = outDir;
    while (base.size() > 1 && base.back() == '/') base.pop_back();
    return base + ".failed";
}

}  // namespace

RunOutputs writeRunOutputs(const report::RunRecord& run, const RunOptions& options, nlohmann::json report,
                           const std::string& outDir, const RunContext& context) {
    StagedDirectory staged(outDir);
    std::vector<std::string> written;
    auto write = [&](const std::string& name, const std::function<void(std::ostream&)>& body) {
        writeOutputAtomic(staged.file(name), body);
        written.push_back(name);
    };
    write("frame.json", [&](std::ostream& out) {
        out << zome::structureToJson(run.frame.structure, run.frameTransformMm).dump(1) << '\n';
    });
    write("frame.vef", [&](std::ostream& out) { out << zome::structureToVef(run.frame.structure); });
    write("partition.json", [&](std::ostream& out) {
        const partition::PartitionJsonInfo info{run.sourceName, "frame.json", run.frameTransformMm,
                                                run.surfaceFrameMm.vertexCount()};
        out << partition::partitionToJson(run.partition, options.partition, info).dump(1) << '\n';
    });
    std::error_code ec;
    if (!std::filesystem::create_directory(staged.file("pieces"), ec))
        throw Error(ErrorCode::WriteFailed, "cannot create the directory: " + ec.message(),
                    staged.file("pieces"));
    pieces::writePieceFiles(run.pieces, staged.file("pieces"),
                            {run.sourceName, "frame.json", "partition.json"});
    written.push_back("pieces/");
    // One 3MF per printer bed, each a print job as it is: next to the preview, not among the STLs.
    pieces::writePlates(run.pieces, run.plates, staged.path());
    written.push_back("plates/");
    report::writePreview(report::previewInput(run), staged.file("preview.glb"), options.preview);
    written.push_back("preview.glb");
    // The same scene as a page that opens offline (three.js inlined, no Draco decoder needed).
    report::writeViewer(report::previewInput(run), options.preview, staged.file("viewer.html"));
    written.push_back("viewer.html");
    write("assembly.md", [&](std::ostream& out) {
        out << report::assemblyGuideMarkdown(run.assembly, options.cost.prices);
    });
    write("assembly.html", [&](std::ostream& out) { out << report::assemblyPage(run, options.cost.prices); });
    write("cost.md", [&](std::ostream& out) { out << report::costPage(run); });
    // The verifier reads back what was written, as `zomefab check` would.
    RunOutputs result;
    result.verification = verify::verifyAssembly(verify::readAssembly(staged.path()), {}, context);
    report["verify"] = verify::verifyReportJson(result.verification);
    write(kRunMarkerFile, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
    result.directory = result.verification.passed() ? outDir : failedDirectory(outDir);
    staged.commitAs(result.directory);
    std::sort(written.begin(), written.end());
    result.files = std::move(written);
    return result;
}

}  // namespace zomefab::pipeline

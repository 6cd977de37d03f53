// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Calibration of the print estimator against PrusaSlicer (not a ctest: it slices ~30 parts
/// and takes a few minutes). Slices each calibration part at 20 % and 100 % infill, fits the
/// sparse-infill factor and the four time rates of report::PrintRates by least squares on
/// relative errors, and prints the Markdown calibration table of docs/report.md for both the fitted and
/// the compiled-in default rates. Usage: report_calibration [--tsv FILE] (prusa-slicer in PATH).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "report_fixtures.h"
#include "zomefab/report/print_estimate.h"
#include "zomefab/report/slicer.h"

using namespace zomefab;
using namespace zomefab::report;

namespace {

struct Sample {
    std::string name;
    double infill = 0.0;
    const TriMesh* mesh = nullptr;
    PrintEstimate model;  ///< with sparseInfillFactor = 1 (the breakdown is what is fitted)
    PrintEstimate slicer;
    double areaMm2 = 0.0;
};

/// Solves the n×n system A x = b (Gaussian elimination, partial pivoting).
std::vector<double> solve(std::vector<std::vector<double>> a, std::vector<double> b) {
    const size_t n = b.size();
    for (size_t c = 0; c < n; ++c) {
        size_t p = c;
        for (size_t r = c + 1; r < n; ++r)
            if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
        std::swap(a[c], a[p]);
        std::swap(b[c], b[p]);
        for (size_t r = c + 1; r < n; ++r) {
            const double f = a[r][c] / a[c][c];
            for (size_t k = c; k < n; ++k) a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    std::vector<double> x(n);
    for (size_t i = n; i-- > 0;) {
        double s = b[i];
        for (size_t k = i + 1; k < n; ++k) s -= a[i][k] * x[k];
        x[i] = s / a[i][i];
    }
    return x;
}

/// Non-negative least squares of rows·x ≈ y on relative errors: refits without the most negative
/// coefficient until all are ≥ 0.
std::vector<double> fitNonNegative(const std::vector<std::vector<double>>& rows,
                                   const std::vector<double>& y) {
    const size_t n = rows[0].size();
    std::vector<char> isFree(n, 1);
    for (;;) {
        std::vector<size_t> idx;
        for (size_t k = 0; k < n; ++k)
            if (isFree[k]) idx.push_back(k);
        std::vector<std::vector<double>> a(idx.size(), std::vector<double>(idx.size(), 0.0));
        std::vector<double> b(idx.size(), 0.0);
        for (size_t r = 0; r < rows.size(); ++r) {
            const double w = 1.0 / (y[r] * y[r]);
            for (size_t i = 0; i < idx.size(); ++i) {
                b[i] += w * rows[r][idx[i]] * y[r];
                for (size_t j = 0; j < idx.size(); ++j) a[i][j] += w * rows[r][idx[i]] * rows[r][idx[j]];
            }
        }
        const std::vector<double> sub = solve(a, b);
        std::vector<double> x(n, 0.0);
        size_t worst = n;
        for (size_t i = 0; i < idx.size(); ++i) {
            x[idx[i]] = sub[i];
            if (sub[i] < 0.0 && (worst == n || sub[i] < x[worst])) worst = idx[i];
        }
        if (worst == n) return x;
        isFree[worst] = 0;
    }
}

void printTable(const std::vector<Sample>& samples, const PrintRates& rates) {
    std::printf(
        "| part | infill | PrusaSlicer h | estimate h | time error | PrusaSlicer cm³ | estimate cm³ | "
        "filament error |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
    double worstTime = 0.0, worstMaterial = 0.0, sumTime = 0.0, sumMaterial = 0.0;
    for (const Sample& s : samples) {
        PrintSettings settings;
        settings.infillPercent = s.infill;
        const PrintEstimate e = estimatePrint(*s.mesh, settings, rates);
        const double te = 100.0 * (e.seconds / s.slicer.seconds - 1.0);
        const double me = 100.0 * (e.filamentMm3 / s.slicer.filamentMm3 - 1.0);
        worstTime = std::max(worstTime, std::abs(te));
        worstMaterial = std::max(worstMaterial, std::abs(me));
        sumTime += te * te, sumMaterial += me * me;
        std::printf("| %s | %.0f%% | %.2f | %.2f | %+.1f%% | %.1f | %.1f | %+.1f%% |\n", s.name.c_str(),
                    s.infill, s.slicer.seconds / 3600.0, e.hours(), te, s.slicer.filamentMm3 / 1000.0,
                    e.filamentMm3 / 1000.0, me);
    }
    const double n = double(samples.size());
    std::printf("\nlargest |error|: time %.1f%%, filament %.1f%%; rms: time %.1f%%, filament %.1f%%\n",
                worstTime, worstMaterial, std::sqrt(sumTime / n), std::sqrt(sumMaterial / n));
}

}  // namespace

int main(int argc, char** argv) {
    if (!isSlicerAvailable("prusa-slicer")) {
        std::fprintf(stderr,
                     "report_calibration: prusa-slicer is not installed (apt-get install prusa-slicer)\n");
        return 1;
    }
    std::string tsv;
    for (int i = 1; i + 1 < argc; ++i)
        if (std::string(argv[i]) == "--tsv") tsv = argv[i + 1];

    const std::vector<std::pair<std::string, TriMesh>> parts = {
        {"cube 20 mm", test::makeBox({0, 0, 0}, {20, 20, 20})},
        {"cube 50 mm", test::makeBox({0, 0, 0}, {50, 50, 50})},
        {"cube 100 mm", test::makeBox({0, 0, 0}, {100, 100, 100})},
        {"slab 150x100x10 mm", test::makeBox({0, 0, 0}, {150, 100, 10})},
        {"tower 20x20x150 mm", test::makeBox({0, 0, 0}, {20, 20, 150})},
        {"sphere 50 mm", test::makeSphere({0, 0, 25}, 25)},
        {"sphere 100 mm", test::makeSphere({0, 0, 50}, 50)},
        {"hollow cube 100 mm, 2 mm walls", test::hollowCube(100, 2)},
        {"hollow cube 100 mm, 16 mm walls", test::hollowCube(100, 16)},
        {"shell piece R 80 mm, 16 mm wall", test::shellPiece(80, 16)},
        {"shell piece R 120 mm, 16 mm wall", test::shellPiece(120, 16)},
        {"shell piece R 60 mm, 4 mm wall", test::shellPiece(60, 4)},
        {"dome piece R 100 mm, 16 mm wall", test::domePiece(100, 16, 50)},
        {"bunny 100 mm", test::bunnyMm(100)},
        {"bunny 150 mm", test::bunnyMm(150)},
    };
    PrintRates unit;  // breakdown only: factor 1
    unit.sparseInfillFactor = 1.0;
    std::vector<Sample> samples;
    for (const auto& [name, mesh] : parts)
        for (double infill : {20.0, 100.0}) {
            PrintSettings s;
            s.infillPercent = infill;
            Sample sample{name,
                          infill,
                          &mesh,
                          estimatePrint(mesh, s, unit),
                          sliceWithPrusaSlicer(mesh, s, name),
                          surfaceArea(mesh)};
            std::fprintf(stderr,
                         "%s %.0f%%: slicer %.0f s %.0f mm3, shell %.0f mm3 infill %.0f mm3 layers %zu\n",
                         name.c_str(), infill, sample.slicer.seconds, sample.slicer.filamentMm3,
                         sample.model.perimeterMm3 + sample.model.solidMm3, sample.model.infillMm3,
                         sample.model.layers);
            samples.push_back(sample);
        }

    // 1. Filament: shell + k·(sparse infill at the nominal density) ≈ slicer, relative errors.
    double num = 0.0, den = 0.0;
    for (const Sample& s : samples) {
        if (s.infill >= 100.0 || s.model.infillMm3 <= 0.0) continue;
        const double shell = s.model.perimeterMm3 + s.model.solidMm3;
        const double w = 1.0 / (s.slicer.filamentMm3 * s.slicer.filamentMm3);
        num += w * s.model.infillMm3 * (s.slicer.filamentMm3 - shell);
        den += w * s.model.infillMm3 * s.model.infillMm3;
    }
    PrintRates fitted;
    fitted.sparseInfillFactor = den > 0.0 ? num / den : 1.0;

    // 2. Time: seconds ≈ Σ volume_k · rate_k.
    std::vector<std::vector<double>> rows;
    std::vector<double> y;
    for (const Sample& s : samples) {
        const bool isSolid = s.infill >= 100.0;
        const double infill = s.model.infillMm3 * (isSolid ? 1.0 : fitted.sparseInfillFactor);
        rows.push_back(
            {s.model.perimeterMm3, s.model.solidMm3, isSolid ? 0.0 : infill, isSolid ? infill : 0.0});
        y.push_back(s.slicer.seconds);
    }
    const std::vector<double> x = fitNonNegative(rows, y);
    fitted.perimeterSPerMm3 = x[0];
    fitted.solidSPerMm3 = x[1];
    fitted.sparseInfillSPerMm3 = x[2];
    fitted.solidInfillSPerMm3 = x[3];

    std::printf(
        "fitted: perimeterSPerMm3 %.4f solidSPerMm3 %.4f sparseInfillSPerMm3 %.4f solidInfillSPerMm3 %.4f "
        "sparseInfillFactor %.4f\n\n",
        fitted.perimeterSPerMm3, fitted.solidSPerMm3, fitted.sparseInfillSPerMm3, fitted.solidInfillSPerMm3,
        fitted.sparseInfillFactor);
    std::printf("## with the fitted rates\n\n");
    printTable(samples, fitted);
    std::printf("\n## with the compiled-in defaults (report::PrintRates{})\n\n");
    printTable(samples, PrintRates{});

    if (!tsv.empty()) {
        std::ofstream out(tsv);
        out << "part\tinfill\tslicer_s\tslicer_mm3\tperimeter_mm3\tsolid_mm3\tinfill_mm3\tlayers\tvolume_"
               "mm3\tarea_mm2\n";
        for (const Sample& s : samples)
            out << s.name << '\t' << s.infill << '\t' << s.slicer.seconds << '\t' << s.slicer.filamentMm3
                << '\t' << s.model.perimeterMm3 << '\t' << s.model.solidMm3 << '\t' << s.model.infillMm3
                << '\t' << s.model.layers << '\t' << s.model.partVolumeMm3 << '\t' << s.areaMm2 << '\n';
    }
    return 0;
}

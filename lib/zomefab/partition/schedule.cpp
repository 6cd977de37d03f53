// SPDX-License-Identifier: GPL-3.0-or-later
// The fit schedule (paper §5.1; docs/partition.md §4) and the printer-fit helpers it uses.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>

#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition::detail {

/// The vertices of @p faces (each once, in first-use order).
std::vector<Vec3d> faceVertices(const TriMesh& mesh, const std::vector<uint32_t>& faces,
                                std::vector<uint32_t>& stamp, uint32_t& stampValue) {
    ++stampValue;
    std::vector<Vec3d> pts;
    for (uint32_t f : faces)
        for (uint32_t v : mesh.triangles[f])
            if (stamp[v] != stampValue) {
                stamp[v] = stampValue;
                pts.push_back(toD(mesh.positions[v]));
            }
    return pts;
}

/// Groups faces by a per-face id: CSR id → faces (in increasing face order).
void groupFaces(const std::vector<uint32_t>& idOf, uint32_t idCount, std::vector<uint32_t>& offsets,
                std::vector<uint32_t>& faces) {
    offsets.assign(size_t(idCount) + 1, 0);
    for (uint32_t id : idOf) ++offsets[id + 1];
    for (uint32_t i = 0; i < idCount; ++i) offsets[i + 1] += offsets[i];
    faces.resize(idOf.size());
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (uint32_t f = 0; f < idOf.size(); ++f) faces[fill[idOf[f]]++] = f;
}

/// Quick accept: an axis-aligned box that fits needs no orientation search.
bool fitsTrivially(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin) {
    Box3d box;
    for (const Vec3d& p : pts) box.expand(p);
    return boxFitsPrinter(box.size(), printer, margin);
}

/// The schedule's fit test (docs/partition.md §4): the quick accept, else the oriented-box search.
bool fitsPrinter(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin) {
    return fitsTrivially(pts, printer, margin) || fitInPrinter(pts, printer, margin).fits;
}

/// Does each of @p faceSets fit the printer (its vertices' oriented box, docs/partition.md §4)?
/// Vertex lists are gathered serially (one stamp array), the fit tests run in parallel; the result
/// does not depend on the thread count.
std::vector<char> fitsEach(FitTester& cx, const std::vector<std::vector<uint32_t>>& faceSets) {
    const size_t n = faceSets.size();
    std::vector<std::vector<Vec3d>> pts(n);
    for (size_t c = 0; c < n; ++c) pts[c] = faceVertices(cx.mesh, faceSets[c], cx.stamp, cx.stampValue);
    std::vector<char> fits(n, 1);
    tbb::parallel_for(size_t(0), n, [&](size_t c) {
        fits[c] = cx.isMountable(faceSets[c]) && fitsPrinter(pts[c], cx.fab.pieceBoxMm(), cx.fab.fitMarginMm);
    });
    return fits;
}

/// Splits @p faces (one class) into parts that each fit the printer, by recursive bisection
/// across the longest axis of the best oriented box, at its middle. Salient regions stay on one
/// side (the side of their first face). Appends the parts to @p parts.
void bisectUntilFit(FitTester& cx, const std::vector<uint32_t>& faces,
                    const std::vector<uint32_t>& salientRegionOf, std::vector<std::vector<uint32_t>>& parts,
                    int depth) {
    const PrinterFit fit = cx.fitOf(faces);
    if (depth > 16 || faces.size() < 2) {
        parts.push_back(faces);
        return;
    }
    if (fit.fits) {
        // It fits the printer; if no direction can mount it, cut off what its best one cannot take.
        std::vector<uint32_t> lo, hi;
        if (cx.isMountable(faces) || !splitUnmountable(cx, faces, lo, hi)) {
            parts.push_back(faces);
            return;
        }
        bisectUntilFit(cx, lo, salientRegionOf, parts, depth + 1);
        bisectUntilFit(cx, hi, salientRegionOf, parts, depth + 1);
        return;
    }
    const Vec3d& axis = fit.axes[2];  // the longest box axis
    const double mid = axis[0] * fit.centerMm[0] + axis[1] * fit.centerMm[1] + axis[2] * fit.centerMm[2];
    auto proj = [&](uint32_t f) {
        const Vec3d& c = cx.graph.centroidsMm[f];
        return axis[0] * c[0] + axis[1] * c[1] + axis[2] * c[2];
    };
    std::map<uint32_t, bool> regionSide;  // salient region → side of its first face
    std::vector<uint32_t> lo, hi;
    for (uint32_t f : faces) {
        bool isHigh = proj(f) >= mid;
        if (salientRegionOf[f] != kNone) {
            auto it = regionSide.find(salientRegionOf[f]);
            if (it == regionSide.end())
                regionSide[salientRegionOf[f]] = isHigh;
            else
                isHigh = it->second;
        }
        (isHigh ? hi : lo).push_back(f);
    }
    if (lo.empty() || hi.empty()) {
        parts.push_back(faces);  // cannot split further (one salient region larger than the printer)
        return;
    }
    bisectUntilFit(cx, lo, salientRegionOf, parts, depth + 1);
    bisectUntilFit(cx, hi, salientRegionOf, parts, depth + 1);
}

/// The fit schedule (docs/partition.md §4). The first step cuts the whole surface at
/// w_smoothness = smoothnessStart and keeps every partition that fits the printer. Each further
/// step multiplies w_smoothness by smoothnessFactor and re-cuts only the faces of the partitions
/// that did not fit, the kept ones held: a single oversized partition no longer sends the whole
/// surface to a lower smoothness (which gave many small pieces), and what already fits stays
/// large and smooth. When w_smoothness would fall below smoothnessMin, what still does not fit
/// is bisected. With refineOversizedOnly = false every step re-cuts the whole surface (the paper).
void runSchedule(const Surface& S, const Problems& P, const PartitionOptions& opt, FitTester& fits,
                 Classes& C, PartitionResult& res, const RunContext& run) {
    const Stopwatch clock;
    FitTester& cx = fits;
    std::vector<uint32_t>& labels = res.graphCutLabels;
    labels.assign(S.faceCount, 0);
    std::vector<char> isFree(S.faceCount, 1);
    // Kept partitions: per face its partition (kNone while free); per partition its label and the
    // step that kept it, which decide its SVM class (below).
    std::vector<uint32_t> regionOf(S.faceCount, kNone), regionLabel;
    std::vector<int> regionStep;
    std::vector<char> isWholeCutStep;              // per step: did it cut the whole surface?
    std::vector<std::vector<uint32_t>> oversized;  // free faces of each partition that does not fit
    std::vector<uint32_t> oversizedLabel;
    double ws = opt.smoothnessStart;
    int step = 0;
    for (;; ++step) {
        const Stopwatch stepClock;
        ScheduleStep st;
        st.smoothnessWeight = ws;
        const bool isWholeCut = step == 0 || !opt.refineOversizedOnly;
        if (isWholeCut) {
            std::fill(isFree.begin(), isFree.end(), char(1));
            std::fill(regionOf.begin(), regionOf.end(), kNone);
        }
        isWholeCutStep.push_back(isWholeCut ? 1 : 0);
        st.faces = size_t(std::count(isFree.begin(), isFree.end(), char(1)));
        const AlphaExpansionResult ae =
            isWholeCut ? graphCut(S, P, opt, run, ws, st) : refineCut(S, P, opt, run, ws, labels, isFree, st);
        st.energyGraphCut = ae.sweepEnergies.back();
        st.sweeps = ae.sweeps;
        st.expansions = ae.expansions;
        for (size_t f = 0; f < S.faceCount; ++f)
            if (isFree[f]) labels[f] = ae.labels[P.units.unitOf[f]];

        // Partitions: connected regions of one label over the whole surface. Only those with free
        // faces are new; the others are kept partitions, unchanged. (Two kept partitions of one
        // label are never edge-adjacent: each was a whole region when it was kept, so a region
        // of its label next to it would have been part of it.)
        std::vector<uint32_t> compOf, compOffsets, compFaces;
        const uint32_t compCount = labelComponents(S.graph, labels, compOf);
        groupFaces(compOf, compCount, compOffsets, compFaces);
        std::vector<std::vector<uint32_t>> candidates;
        for (uint32_t c = 0; c < compCount; ++c) {
            const auto b = compFaces.begin() + compOffsets[c], e = compFaces.begin() + compOffsets[c + 1];
            if (std::any_of(b, e, [&](uint32_t f) { return isFree[f] != 0; })) candidates.emplace_back(b, e);
        }
        const std::vector<char> fits = fitsEach(cx, candidates);
        oversized.clear();
        oversizedLabel.clear();
        for (size_t i = 0; i < candidates.size(); ++i) {
            const uint32_t label = labels[candidates[i].front()];
            if (fits[i]) {
                // Kept, together with any kept partition its free faces joined (the union fits).
                const uint32_t r = uint32_t(regionLabel.size());
                regionLabel.push_back(label);
                regionStep.push_back(step);
                for (uint32_t f : candidates[i]) regionOf[f] = r, isFree[f] = 0;
                ++st.kept;
            } else {
                // Its kept faces stay kept; its free faces are cut again at the next step.
                std::vector<uint32_t> freeFaces;
                for (uint32_t f : candidates[i])
                    if (isFree[f]) freeFaces.push_back(f);
                oversized.push_back(std::move(freeFaces));
                oversizedLabel.push_back(label);
            }
        }
        st.partitions = compCount;
        st.oversized = oversized.size();
        st.seconds = stepClock.seconds();
        res.schedule.push_back(st);
        res.smoothnessWeight = ws;
        res.energyNearest = st.energyNearest;
        res.energyGraphCut = st.energyGraphCut;
        res.sweepEnergies = ae.sweepEnergies;
        res.graphCutPartitions = st.partitions;
        run.detail(formatNumbers("w_smoothness %g: ", ws) +
                   (isWholeCut ? std::string()
                               : "re-cut " + std::to_string(st.faces) +
                                     " faces of the partitions that did not fit, ") +
                   formatNumbers("E %.6g -> %.6g, %.0f partitions", st.energyNearest, st.energyGraphCut,
                                 double(st.partitions)) +
                   (oversized.empty() ? ", all fit the printer"
                                      : ", " + std::to_string(oversized.size()) + " too large"));
        if (!ae.isConverged)
            run.warn(formatNumbers("graph cut at w_smoothness %g stopped after %.0f sweeps before converging",
                                   ws, double(ae.sweeps)));
        run.progress("partition", std::min(0.6, 0.1 * (step + 1)));
        if (oversized.empty()) break;
        if (ws * opt.smoothnessFactor < opt.smoothnessMin * (1.0 - 1e-9) || ws == 0.0) {
            res.isScheduleBottomedOut = true;
            break;
        }
        ws *= opt.smoothnessFactor;
    }
    res.secondsGraphCut = clock.seconds();

    // SVM training classes. Class l = label l for the partitions a whole-surface cut kept (as in
    // the paper: one class per ball); a partition kept by a re-cut gets a class per (step, label),
    // so it is never one class with a kept partition of the same ball next to it.
    C.classBall.assign(S.labelBalls.begin(), S.labelBalls.end());
    std::map<std::pair<int, uint32_t>, uint32_t> classOfKey;
    auto classFor = [&](int keptStep, uint32_t label) {
        if (isWholeCutStep[size_t(keptStep)]) return label;
        auto it = classOfKey.find({keptStep, label});
        if (it != classOfKey.end()) return it->second;
        C.classBall.push_back(S.labelBalls[label]);
        const uint32_t c = uint32_t(C.classBall.size() - 1);
        classOfKey.emplace(std::make_pair(keptStep, label), c);
        return c;
    };
    std::vector<uint32_t> regionClass(regionLabel.size());
    for (size_t r = 0; r < regionLabel.size(); ++r) regionClass[r] = classFor(regionStep[r], regionLabel[r]);
    C.trainClass.assign(S.faceCount, 0);
    for (size_t f = 0; f < S.faceCount; ++f)
        if (regionOf[f] != kNone) C.trainClass[f] = regionClass[regionOf[f]];
    // The schedule bottomed out: bisect what still does not fit. Its first part keeps the class
    // of its (step, label), every other part gets a class of its own.
    for (size_t i = 0; i < oversized.size(); ++i) {
        const uint32_t c = classFor(step, oversizedLabel[i]);
        for (uint32_t f : oversized[i]) C.trainClass[f] = c;
        res.splits += splitFaces(S, res, C, fits, oversized[i]) ? 1 : 0;
    }
    if (res.isScheduleBottomedOut)
        run.warn(formatNumbers(
            "the fit schedule bottomed out at w_smoothness %g with %.0f partitions larger than the "
            "printer; split them",
            ws, double(oversized.size())));
}

/// A new training class for @p faces, attached to the ball most of them are nearest to
/// (lowest label on ties).
uint32_t newClassFor(const Surface& S, const PartitionResult& res, Classes& C,
                     const std::vector<uint32_t>& faces) {
    std::map<uint32_t, size_t> votes;
    for (uint32_t f : faces) ++votes[res.nearestLabels[f]];
    uint32_t best = votes.begin()->first;
    for (const auto& [l, n] : votes)
        if (n > votes[best]) best = l;
    C.classBall.push_back(S.labelBalls[best]);
    return uint32_t(C.classBall.size() - 1);
}

/// Bisects @p faces until the parts fit; every part but the first gets a new class.
bool splitFaces(const Surface& S, const PartitionResult& res, Classes& C, FitTester& fits,
                const std::vector<uint32_t>& faces) {
    std::vector<std::vector<uint32_t>> parts;
    bisectUntilFit(fits, faces, S.salientRegionOf, parts, 0);
    for (size_t p = 1; p < parts.size(); ++p) {
        const uint32_t c = newClassFor(S, res, C, parts[p]);
        for (uint32_t f : parts[p]) C.trainClass[f] = c;
    }
    return parts.size() > 1;
}

}  // namespace zomefab::partition::detail

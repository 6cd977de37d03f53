// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/fabrication.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"

namespace zomefab {

uint64_t seedFor(const Fabrication& fabrication, SeedStream stream) {
    switch (stream) {
        case SeedStream::Frame:
        case SeedStream::Partition:
            return fabrication.seed;
    }
    return fabrication.seed;
}

namespace {

void requireRange(double value, double lo, double hi, const char* option, const char* unit) {
    if (!(value >= lo && value <= hi))
        throw Error(ErrorCode::Usage, std::string(option) + " must be in [" + formatNumber(lo) + ", " +
                                          formatNumber(hi) + "] " + unit + ", got " + formatNumber(value));
}

}  // namespace

Vec3d pieceBoxMm(const Vec3d& printerMm, double bedMarginMm) {
    return {printerMm[0] - 2.0 * bedMarginMm, printerMm[1] - 2.0 * bedMarginMm, printerMm[2]};
}

Vec3d Fabrication::pieceBoxMm() const { return zomefab::pieceBoxMm(printerMm, bedMarginMm); }

void checkFabrication(const Fabrication& f) {
    for (double side : f.printerMm)
        if (!(side > 0.0) || !std::isfinite(side) || side > 10000.0)
            throw Error(ErrorCode::Usage,
                        "--printer-mm: every side must be in (0, 10000] mm, got " +
                            formatNumbers("%g x %g x %g", f.printerMm[0], f.printerMm[1], f.printerMm[2]));
    requireRange(f.fitMarginMm, 0.0, 100.0, "--fit-margin-mm", "mm");
    requireRange(f.bedMarginMm, 0.0, 100.0, "--bed-margin-mm", "mm");
    if (!(std::min(f.printerMm[0], f.printerMm[1]) > 2.0 * f.bedMarginMm))
        throw Error(ErrorCode::Usage, formatNumbers("--bed-margin-mm %g leaves nothing of the %g x %g mm bed",
                                                    f.bedMarginMm, f.printerMm[0], f.printerMm[1]));
    requireRange(f.wallMm, 1.0, 200.0, "--shell-mm", "mm");
    requireRange(f.frameClearanceMm, 0.0, 1000.0, "--frame-clearance-mm", "mm");
    requireRange(f.wallGapMm, 0.0, 100.0, "--wall-gap-mm", "mm");
    requireRange(f.b0Mm, 1.0, 1000.0, "--b0-mm", "mm");
    requireRange(f.overhangDeg, 10.0, 80.0, "--overhang-deg", "degrees");
}

bool boxFitsPrinter(const Vec3d& sizeMm, const Vec3d& printerMm, double marginMm, double toleranceMm) {
    Vec3d e = sizeMm;
    for (double& x : e) x += 2 * marginMm;
    Vec3d p = printerMm;
    std::sort(e.begin(), e.end());
    std::sort(p.begin(), p.end());
    return e[0] <= p[0] + toleranceMm && e[1] <= p[1] + toleranceMm && e[2] <= p[2] + toleranceMm;
}

}  // namespace zomefab

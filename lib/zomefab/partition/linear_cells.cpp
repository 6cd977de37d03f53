// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/linear_cells.h"

#include <linear.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>

#include "zomefab/core/error.h"

namespace zomefab::partition {

uint32_t LinearCells::cellAt(const Vec3d& x) const {
    uint32_t best = 0;
    double bestScore = score(0, x);
    for (uint32_t k = 1; k < cellCount(); ++k) {
        const double s = score(k, x);
        if (s > bestScore) best = k, bestScore = s;
    }
    return best;
}

namespace {

void silentPrint(const char*) {}

std::mutex& liblinearMutex() {
    static std::mutex m;
    return m;
}

}  // namespace

LinearCells trainLinearCells(const std::vector<Vec3d>& pts, const std::vector<uint32_t>& classes,
                             const CellTrainingOptions& options) {
    if (pts.empty() || pts.size() != classes.size())
        throw Error(ErrorCode::Usage, "cell training: " + std::to_string(pts.size()) + " points and " +
                                          std::to_string(classes.size()) + " classes");
    LinearCells cells;
    std::vector<uint32_t> distinct(classes.begin(), classes.end());
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    if (distinct.size() == 1) {
        cells.w = {Vec3d{0, 0, 0}};
        cells.b = {0.0};
        cells.classes = distinct;
        return cells;
    }

    // Feature scaling: uniform, so the max-margin geometry is the one in millimetres.
    Box3d box;
    for (const Vec3d& p : pts) box.expand(p);
    const Vec3d c{0.5 * (box.min[0] + box.max[0]), 0.5 * (box.min[1] + box.max[1]),
                  0.5 * (box.min[2] + box.max[2])};
    const Vec3d size = box.size();
    const double s = std::max(0.5 * std::max({size[0], size[1], size[2]}), 1e-9);

    // liblinear problem: 3 features + bias (index 4), each row terminated by index −1.
    const size_t n = pts.size();
    std::vector<feature_node> nodes(n * 5);
    std::vector<feature_node*> rows(n);
    std::vector<double> y(n);
    for (size_t i = 0; i < n; ++i) {
        feature_node* r = &nodes[i * 5];
        for (int j = 0; j < 3; ++j) r[j] = {j + 1, (pts[i][size_t(j)] - c[size_t(j)]) / s};
        r[3] = {4, 1.0};  // bias feature (problem.bias = 1)
        r[4] = {-1, 0.0};
        rows[i] = r;
        y[i] = double(classes[i]);
    }
    problem prob{};
    prob.l = int(n);
    prob.n = 4;
    prob.y = y.data();
    prob.x = rows.data();
    prob.bias = 1.0;
    parameter param{};
    param.solver_type = options.useCrammerSinger ? MCSVM_CS : L2R_L2LOSS_SVC_DUAL;
    param.eps = options.tolerance;
    param.C = options.cost;
    param.nr_weight = 0;
    param.weight_label = nullptr;
    param.weight = nullptr;
    param.p = 0.1;
    param.init_sol = nullptr;
    if (const char* err = check_parameter(&prob, &param))
        throw Error(ErrorCode::Internal, std::string("liblinear: ") + err);

    model* m = nullptr;
    {
        // liblinear prints to stdout unless told otherwise and shuffles with rand(): both global.
        std::lock_guard<std::mutex> lock(liblinearMutex());
        set_print_string_function(&silentPrint);
        std::srand(unsigned(options.seed ^ (options.seed >> 32)));
        m = train(&prob, &param);
    }
    if (!m) throw Error(ErrorCode::Internal, "liblinear: training failed");
    const int k = m->nr_class;
    // MCSVM_CS and one-vs-rest with > 2 classes store nr_class weight vectors, interleaved:
    // w[feature * nr_class + class]. One-vs-rest with 2 classes stores one vector for class 0
    // against class 1: turn it into the equivalent pair (+w/2, −w/2).
    const bool isSingleVector = k == 2 && !options.useCrammerSinger;
    cells.w.resize(size_t(k));
    cells.b.resize(size_t(k));
    cells.classes.resize(size_t(k));
    for (int cls = 0; cls < k; ++cls) {
        double wp[4];
        for (int f = 0; f < 4; ++f) {
            if (isSingleVector)
                wp[f] = (cls == 0 ? 0.5 : -0.5) * m->w[f];
            else
                wp[f] = m->w[f * k + cls];
        }
        Vec3d w{wp[0] / s, wp[1] / s, wp[2] / s};
        cells.w[size_t(cls)] = w;
        cells.b[size_t(cls)] = wp[3] * 1.0 - (w[0] * c[0] + w[1] * c[1] + w[2] * c[2]);
        cells.classes[size_t(cls)] = uint32_t(m->label[cls]);
    }
    free_and_destroy_model(&m);
    // Cells in increasing class order, so the numbering does not depend on sample order.
    std::vector<size_t> order(static_cast<size_t>(k));
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return cells.classes[a] < cells.classes[b]; });
    LinearCells sorted;
    for (size_t i : order) {
        sorted.w.push_back(cells.w[i]);
        sorted.b.push_back(cells.b[i]);
        sorted.classes.push_back(cells.classes[i]);
    }
    return sorted;
}

}  // namespace zomefab::partition

// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Planar cuts (paper §5.2) as the cells of one multi-class linear model trained with
/// Debian's liblinear: cell k = {x : w_k·x + b_k ≥ w_j·x + b_j for every j}, ties going to the
/// lowest k. Each cell is an intersection of half-spaces (w_k − w_j)·x + (b_k − b_j) ≥ 0, hence a
/// convex polyhedron, and argmax assigns every point of space to exactly one cell: no gaps, no
/// overlaps. The pairwise planes between cells k and j are (w_k − w_j)·x + (b_k − b_j) = 0.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::partition {

/// The trained cells, in millimetres (the training points' frame).
struct LinearCells {
    std::vector<Vec3d> w;           ///< per cell, 1/mm
    std::vector<double> b;          ///< per cell, dimensionless
    std::vector<uint32_t> classes;  ///< per cell: the training class it stands for

    size_t cellCount() const { return w.size(); }
    /// w_k·x + b_k
    double score(uint32_t cell, const Vec3d& xMm) const {
        return w[cell][0] * xMm[0] + w[cell][1] * xMm[1] + w[cell][2] * xMm[2] + b[cell];
    }
    /// argmax_k score(k, x), the lowest k on ties.
    uint32_t cellAt(const Vec3d& xMm) const;
};

struct CellTrainingOptions {
    /// liblinear cost C: larger follows the labels more closely (fewer misclassified samples), at
    /// the cost of a smaller margin and a longer training. Features are scaled to [−1, 1].
    double cost = 10.0;
    double tolerance = 0.1;  ///< liblinear stopping tolerance eps (liblinear's default for MCSVM_CS)
    /// true: Crammer–Singer multi-class SVM (MCSVM_CS), one joint problem; false: one-vs-rest
    /// L2-loss SVMs (L2R_L2LOSS_SVC_DUAL). Both give an argmax model with convex cells.
    bool useCrammerSinger = true;
    uint64_t seed = 1;  ///< seeds liblinear's sample shuffling (it uses rand())
};

/// Trains the cells on @p pointsMm with class ids @p classes (any uint32 values, several per
/// point set). Features are x' = (x − c)/s with c the centre of the points' bounding box and s
/// half its largest side, plus a bias feature 1; the model is mapped back to mm:
/// w_k = w'_k / s, b_k = w'_bias,k − w_k·c. One class gives one cell covering space (w = 0, b = 0).
/// Deterministic for a given seed (serialised: liblinear keeps global state).
/// @throw Error(Usage) when the sizes differ or there are no points.
LinearCells trainLinearCells(const std::vector<Vec3d>& pointsMm, const std::vector<uint32_t>& classes,
                             const CellTrainingOptions& options = {});

}  // namespace zomefab::partition

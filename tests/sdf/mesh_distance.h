// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Exact point-to-triangle-mesh distance for the sdf tests and benchmark: an independent
/// reference (no OpenVDB) to check level sets, meshing and the interior field against.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::test {

/// Nearest point on a triangle mesh, found through a uniform grid of triangle bins. Read-only after
/// construction, so concurrent queries are safe.
class MeshDistance {
public:
    /// @p cellMm: bin size; 0 picks about four mean triangle sizes.
    explicit MeshDistance(const TriMesh& mesh, double cellMm = 0);
    /// Unsigned distance from @p p to the mesh; the nearest point in @p closest when given.
    double distance(const Vec3d& p, Vec3d* closest = nullptr) const;

private:
    const TriMesh& mMesh;
    Vec3d mOrigin{0, 0, 0};
    double mCell = 1;
    int mDims[3] = {1, 1, 1};
    std::vector<uint32_t> mStart;  ///< CSR offsets, one per cell + 1
    std::vector<uint32_t> mItems;  ///< triangle indices
};

/// @p count points spread over the surface with probability proportional to area (fixed @p seed);
/// the triangle each lies on appended to @p facets when given.
std::vector<Vec3d> sampleSurface(const TriMesh& mesh, size_t count, uint32_t seed,
                                 std::vector<uint32_t>* facets = nullptr);

/// The @p q quantile (0..1) of @p values (copied, partially sorted).
double quantile(std::vector<double> values, double q);

/// Distances from each of @p points to @p mesh.
std::vector<double> distancesTo(const MeshDistance& mesh, const std::vector<Vec3d>& points);

/// Edge topology of a triangle mesh.
struct EdgeReport {
    size_t boundaryEdges = 0;     ///< used by one triangle
    size_t nonManifoldEdges = 0;  ///< used by three or more
    size_t misorientedEdges = 0;  ///< two-triangle edges traversed the same way by both
    size_t components = 0;        ///< edge-connected components
    std::vector<uint32_t> componentOfTriangle;
};
EdgeReport edgeReport(const TriMesh& mesh);

/// The triangles of component @p c (vertices shared with the input, unreferenced ones kept).
TriMesh extractComponent(const TriMesh& mesh, const EdgeReport& report, uint32_t c);

}  // namespace zomefab::test

// SPDX-License-Identifier: GPL-3.0-or-later
// A piece's mesh checked and turned for the printer (detail/stages.h, docs/pieces.md §4–5).
#include <algorithm>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/pieces/detail/stages.h"
#include "zomefab/pieces/orientation.h"

namespace zomefab::pieces::detail {

namespace {

/// The planes between the piece's cells and the others, outward into the other cell.
std::vector<CutFace> cutPlanes(const GridCells& cells, const CellSet& set, double seamGapMm) {
    const size_t cellCount = cells.count();
    std::vector<CutFace> planes;
    for (uint32_t k : set.isLining ? std::vector<uint32_t>() : set.members)
        for (uint32_t j = 0; j < cellCount; ++j) {
            if (set.isMember[j]) continue;
            const double inv = cells.invNorm[k * cellCount + j];
            if (inv <= 0) continue;
            planes.push_back(
                {scale(sub(cells.w[j], cells.w[k]), inv), (cells.b[j] - cells.b[k]) * inv + seamGapMm, 0.0});
        }
    // A re-cut plane normal·x = offset is the plane normal·x − offset = 0.
    for (const CellSet::HalfSpace& h : set.halfSpaces)
        planes.push_back({h.normal, seamGapMm - h.offsetMm, 0.0});
    return planes;
}

[[noreturn]] void failFit(const Piece& piece, const PrintOrientation& orientation, const Vec3d& printerMm) {
    const Vec3d e = orientation.extentsMm;
    const double overshootMm = std::max({e[0] - printerMm[0], e[1] - printerMm[1], e[2] - printerMm[2], 0.0});
    throw PieceTooLarge("piece " + std::to_string(piece.id) + " (" + formatNumber(e[0], 4) + " × " +
                            formatNumber(e[1], 4) + " × " + formatNumber(e[2], 4) + " mm at best) fits the " +
                            formatNumber(printerMm[0], 4) + " × " + formatNumber(printerMm[1], 4) + " × " +
                            formatNumber(printerMm[2], 4) +
                            " mm printer in no orientation: the partition must cut it smaller (zf-partition "
                            "--printer-mm, --fit-margin-mm)",
                        overshootMm);
}

/// The cut face on the bed made exactly flat: where the mesher's rounding put a vertex up to the
/// flat tolerance beyond the face's plane (at a rim), it is moved onto the plane, and the plane is
/// z = 0. The face then prints as the first layer whole.
void flattenBase(TriMesh& mesh, const std::vector<CutFace>& faces, const PrintOrientation& orientation,
                 Piece& piece) {
    const auto face = std::find_if(faces.begin(), faces.end(), [&](const CutFace& f) {
        return dot(f.outwardNormal, orientation.downNormal) > 1 - 1e-12;
    });
    if (face == faces.end()) return;
    // A point of the plane, in printer coordinates.
    const double planeZ = orientation.transformMm.apply(scale(face->outwardNormal, -face->offsetMm))[2];
    for (Vec3f& v : mesh.positions) v[2] = float(std::max(double(v[2]), planeZ) - planeZ);
    Transform4d lift = Transform4d::identity();
    lift.m[11] = -planeZ;
    piece.gridToPrintMm = lift * orientation.transformMm;
}

}  // namespace

std::string finishPiece(Piece& piece, TriMesh mesh, const GridCells& cells, const CellSet& set,
                        const Fabrication& fabrication, double voxel, double seamGapMm,
                        const RunContext& context) {
    // Sealed pockets of a few voxels (seen up to 28 voxels, where a tenon prism meets a tilted
    // wall) would be printed as empty pockets and make admesh count extra parts: fill them. An
    // uncut closed shell keeps its hollow, which is far larger.
    const mesh::CavityRemoval cavities = mesh::removeCavities(mesh, 1000.0 * voxel * voxel * voxel);
    if (cavities.cavities > 0)
        context.debug("piece " + std::to_string(piece.id) + ": filled " + std::to_string(cavities.cavities) +
                      " sealed cavities of " + formatNumber(cavities.volumeMm3, 4) + " mm³");
    const mesh::MeshReport report = mesh::checkMesh(mesh);
    if (report.boundaryEdges > 0 || report.nonManifoldEdges > 0 || !(report.volume > 0))
        throw Error(ErrorCode::ProcessingFailed,
                    "piece " + std::to_string(piece.id) + ": the mesh is not a closed, outward surface (" +
                        std::to_string(report.boundaryEdges) + " boundary and " +
                        std::to_string(report.nonManifoldEdges) + " non-manifold edges, volume " +
                        formatNumber(report.volume, 4) + " mm³)");
    piece.volumeMm3 = report.volume;
    piece.gridBoundsMm = boundingBox(mesh);
    const std::vector<CutFace> faces = measureCutFaces(mesh, cutPlanes(cells, set, seamGapMm), 0.05 * voxel);
    // Oriented within the bed less its margins, then centred on the bed.
    const Vec3d box = fabrication.pieceBoxMm();
    const double bedMarginMm = fabrication.bedMarginMm;
    PrintOrientation orientation =
        orientForPrinter(mesh, faces, box, kFlatToleranceMm, fabrication.overhangDeg);
    if (!orientation.fits) failFit(piece, orientation, box);
    orientation.transformMm.m[3] += bedMarginMm;
    orientation.transformMm.m[7] += bedMarginMm;
    piece.gridToPrintMm = orientation.transformMm;  // flattenBase may lift it a few hundredths
    piece.isCutFaceDown = orientation.isCutFaceDown;
    piece.isOnSupports = orientation.isOnSupports;
    piece.downNormalGridMm = orientation.downNormal;
    piece.baseAreaMm2 = orientation.baseAreaMm2;
    piece.supportAreaMm2 = orientation.support.areaMm2;
    piece.supportVolumeMm3 = orientation.support.volumeMm3;
    piece.extentsMm = orientation.extentsMm;
    transformInPlace(mesh, orientation.transformMm);
    if (orientation.isCutFaceDown) {
        flattenBase(mesh, faces, orientation, piece);
        piece.baseAreaMm2 = baseAreaMm2(mesh, {0, 0, -1});
    }
    piece.isBrimAdvised = piece.baseAreaMm2 < kBrimBelowMm2;
    // The adaptive mesher can emit two points a float's rounding apart (seen where a tenon off the
    // lattice axes meets a curved wall); turned onto the bed they can round to the same point.
    // Welded, the zero-area triangles between them repeat a vertex and go, so the STL has no
    // degenerate facet.
    weldIdenticalVertices(mesh);
    mesh.triangles.erase(std::remove_if(mesh.triangles.begin(), mesh.triangles.end(), hasRepeatedIndex),
                         mesh.triangles.end());
    // It can also emit points a few float roundings apart that are not identical, and three points
    // in a row (both seen where a stem meets a thin wall): short edges are collapsed (0.1 µm, far
    // below a printer's resolution), needles flipped.
    collapseShortEdges(mesh, 1e-4);
    flipNeedles(mesh);
    piece.mesh = std::move(mesh);
    return orientation.note;
}

}  // namespace zomefab::pieces::detail

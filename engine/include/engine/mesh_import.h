// engine/mesh_import.h -- triangle meshes from files through assimp (assimp stays in the .cpp),
// with a report of what the import changed in the file's geometry.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "collision/geometry/shape.h"

namespace engine {

/// What importing changed, in the file's units (before `scale`). assimp (as Debian builds it)
/// holds coordinates in float: a mesh far from its own origin loses the digits that tell its
/// vertices apart, and its triangles collapse.
struct MeshImportReport {
    std::int64_t triangles_read = 0;      ///< the file's faces, triangulated
    std::int64_t degenerate_dropped = 0;  ///< of those, dropped: a repeated vertex or no area
    /// Of those dropped, when the coordinates were checked (below): degenerate in the file's own
    /// coordinates too, or only after rounding to float. A triangle whose corners cannot be
    /// matched to the file's points is in neither.
    std::int64_t degenerate_in_file = 0;
    std::int64_t degenerate_by_rounding = 0;
    /// The file's coordinates were read in double too (OBJ, OFF, ASCII PLY, ASCII STL), so the
    /// figures below are measured; else they are 0 and unknown.
    bool coordinates_checked = false;
    /// Distinct vertex positions of the file that rounding to float made coincide.
    std::int64_t vertices_merged = 0;
    collision::Real max_coordinate = 0;  ///< largest |coordinate| of the file
    collision::Real max_rounding = 0;    ///< largest |file - imported| of one coordinate
    collision::Real size = 0;            ///< diagonal of the file's vertices' bounding box
    /// The coordinates were handed to assimp relative to `offset` (their bounding box centre,
    /// added back in double) because they lie far from the origin for their size.
    bool recentred = false;
    collision::Vec3 offset = collision::Vec3::Zero();

    /// Anything lost: a triangle dropped, vertices merged, or a coordinate rounded by more than
    /// 2^-20 of the mesh's size (16 times what float gives a mesh around its own origin).
    bool changed() const;
};

struct MeshImportOutput {
    bool ok = false;
    std::string error;  ///< "cannot open", assimp's message, "no triangles", "non-finite vertex"
    collision::TriangleMesh mesh;
    MeshImportReport report;  ///< also filled when the import failed for lack of triangles
};

/// Loads every mesh of the file, merged, triangulated, identical vertices joined, scaled by
/// `scale` (> 0). Degenerate (zero-area) triangles are dropped and counted in the report. Text
/// formats far from their origin (coordinates beyond 16 times the mesh's size) are passed to
/// assimp recentred, so float rounds relative to the mesh, not to its distance from the origin.
MeshImportOutput importMesh(const std::filesystem::path& file, collision::Real scale);

/// One sentence saying what the import changed and the way out (move the mesh's coordinates
/// near its own origin, place it with the body's position), or "" when report.changed() is
/// false.
std::string describeImportChanges(const MeshImportReport& report);

}  // namespace engine

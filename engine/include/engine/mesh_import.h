// engine/mesh_import.h -- triangle meshes from files through assimp (assimp stays in the .cpp).
#pragma once

#include <filesystem>
#include <string>

#include "collision/geometry/shape.h"

namespace engine {

struct MeshImportOutput {
    bool ok = false;
    std::string error;  ///< "cannot open", assimp's message, "no triangles", "non-finite vertex"
    collision::TriangleMesh mesh;
};

/// Loads every mesh of the file, merged, triangulated, identical vertices joined, scaled by
/// `scale` (> 0). Degenerate (zero-area) triangles are dropped.
MeshImportOutput importMesh(const std::filesystem::path& file, collision::Real scale);

}  // namespace engine

// engine/src/mesh_text_coordinates.h -- the vertex coordinates of text model files (OBJ, OFF,
// ASCII PLY, ASCII STL) read in double, and the same text with them shifted: mesh import
// (mesh_import.cpp) measures what assimp's float coordinates lose, and hands assimp a mesh far
// from the origin recentred, so that float rounds relative to the mesh's size.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "collision/math.h"

namespace engine {

struct TextCoordinates {
    bool ok = false;       ///< a format read here, and every vertex line held three numbers
    std::string text;      ///< the whole file
    std::string hint;      ///< its extension for assimp ("obj", "off", "ply", "stl")
    std::vector<collision::Vec3> points;  ///< each vertex as written, in file order
    /// Byte range [first, second) of each written coordinate, 3 per point, x y z.
    std::vector<std::pair<std::size_t, std::size_t>> spans;
};

/// The coordinates of `file` when it is OBJ (`v` lines), OFF, ASCII PLY (x, y, z of the
/// `vertex` element) or ASCII STL (`vertex` lines), chosen by extension and checked against the
/// content; `ok` false for every other format and for any line that does not parse (assimp then
/// reads the file alone). Linear in the file size.
TextCoordinates readTextCoordinates(const std::filesystem::path& file);

/// `tc.text` with every coordinate replaced by (its value - offset) to 17 significant digits
/// (round-trips a double). Everything else is unchanged.
std::string shiftedText(const TextCoordinates& tc, const collision::Vec3& offset);

}  // namespace engine

// engine/src/mesh_import.cpp -- assimp -> collision::TriangleMesh. The only file that sees assimp.
// Output invariant: vertices are unique by position (welded exactly, after scaling), every vertex
// is used, every triangle has three distinct vertices and non-zero area, and the order of both
// follows the file (meshes in scene order, faces in mesh order), so imports are deterministic.
#include "engine/mesh_import.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <exception>
#include <map>
#include <system_error>
#include <utility>
#include <vector>

namespace engine {

namespace {

using collision::Real;
using collision::Vec3;

// A triangle is degenerate when |(b-a) x (c-a)| is at rounding level of its longest edge squared.
constexpr Real kDegenerateArea = Real(4) * collision::kEpsilon;

}  // namespace

MeshImportOutput importMesh(const std::filesystem::path& file, collision::Real scale) {
    MeshImportOutput out;
    if (!(scale > 0) || !std::isfinite(scale)) {
        out.error = "scale must be finite and > 0";
        return out;
    }
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) {
        out.error = "cannot open '" + file.string() + "': no such file";
        return out;
    }
    if (!std::filesystem::is_regular_file(file, ec)) {
        out.error = "cannot open '" + file.string() + "': not a regular file";
        return out;
    }

    Assimp::Importer importer;
    // Only positions matter: drop normals, UVs and colours before JoinIdenticalVertices so that
    // vertices split at normal seams are joined again, and drop point and line primitives.
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                                aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                    aiComponent_COLORS | aiComponent_TEXCOORDS |
                                    aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                    aiComponent_TEXTURES | aiComponent_LIGHTS |
                                    aiComponent_CAMERAS | aiComponent_MATERIALS);
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_RemoveComponent | aiProcess_Triangulate |
                           aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                           aiProcess_SortByPType | aiProcess_ValidateDataStructure;
    const aiScene* scene = nullptr;
    try {
        scene = importer.ReadFile(file.string(), flags);
    } catch (const std::exception& e) {
        out.error = std::string("assimp failed: ") + e.what();
        return out;
    } catch (...) {
        out.error = "assimp failed";
        return out;
    }
    if (scene == nullptr) {
        std::string why = importer.GetErrorString();
        if (why.empty()) why = "unknown error";
        out.error = "cannot read '" + file.string() + "': " + why;
        return out;
    }

    // Merge every mesh, welding equal positions across meshes too (exact comparison: the file's
    // shared vertices are bit-identical after the same transform and scale).
    std::map<std::array<Real, 3>, std::int32_t> index_of;
    collision::TriangleMesh& mesh = out.mesh;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
        const aiMesh* am = scene->mMeshes[mi];
        if (am == nullptr || am->mVertices == nullptr) continue;
        std::vector<std::int32_t> local(am->mNumVertices, -1);
        for (unsigned fi = 0; fi < am->mNumFaces; ++fi) {
            const aiFace& face = am->mFaces[fi];
            if (face.mNumIndices != 3) continue;
            std::array<std::int32_t, 3> tri{};
            bool valid = true;
            for (int k = 0; k < 3; ++k) {
                const unsigned vi = face.mIndices[k];
                if (vi >= am->mNumVertices) {
                    valid = false;
                    break;
                }
                if (local[vi] < 0) {
                    const aiVector3D& v = am->mVertices[vi];
                    const Vec3 p = Vec3(Real(v.x), Real(v.y), Real(v.z)) * scale;
                    if (!p.allFinite()) {
                        out.error = "non-finite vertex in '" + file.string() + "'";
                        return out;
                    }
                    const std::array<Real, 3> key = {p.x(), p.y(), p.z()};
                    const auto [it, inserted] =
                        index_of.emplace(key, static_cast<std::int32_t>(mesh.vertices.size()));
                    if (inserted) mesh.vertices.push_back(p);
                    local[vi] = it->second;
                }
                tri[k] = local[vi];
            }
            if (!valid) continue;
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;
            const Vec3& a = mesh.vertices[tri[0]];
            const Vec3& b = mesh.vertices[tri[1]];
            const Vec3& c = mesh.vertices[tri[2]];
            const Real longest2 =
                std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
            if (!((b - a).cross(c - a).norm() > kDegenerateArea * longest2)) continue;
            mesh.triangles.push_back(tri);
        }
    }
    if (mesh.triangles.empty()) {
        mesh = {};
        out.error = "no triangles in '" + file.string() + "'";
        return out;
    }
    // Drop vertices only referenced by dropped triangles, keeping first-use order.
    std::vector<std::int32_t> remap(mesh.vertices.size(), -1);
    std::vector<Vec3> used;
    for (auto& t : mesh.triangles) {
        for (std::int32_t& v : t) {
            if (remap[v] < 0) {
                remap[v] = static_cast<std::int32_t>(used.size());
                used.push_back(mesh.vertices[v]);
            }
            v = remap[v];
        }
    }
    mesh.vertices = std::move(used);
    out.ok = true;
    return out;
}

}  // namespace engine

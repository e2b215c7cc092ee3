// collision/src/bvh/reference.cpp -- the brute-force references every BVH query is tested
// against: all triangle pairs (after an exact per-triangle box reject), the same exact tests and
// the same vertex transform; and the sweep along x that gives the same list faster.
#include <algorithm>
#include <limits>
#include <vector>

#include "bvh/traversal.h"
#include "collision/bvh/bvh.h"
#include "geometry/triangle_distance.h"
#include "geometry/triangle_triangle.h"
#include "volumes/bvh_volumes.h"

namespace collision {

MeshDistance distanceMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                        const Pose& b_in_a, BvhQueryStats* stats) {
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);  // the BVH query's transform
    MeshDistance out;
    out.distance = std::numeric_limits<Real>::infinity();
    std::vector<std::array<Vec3, 3>> moved(b.triangles.size());
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
        for (std::size_t k = 0; k < 3; ++k) {
            moved[j][k] = x.apply(b.vertices[static_cast<std::size_t>(b.triangles[j][k])]);
        }
    }
    std::int64_t tests = 0;
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
        const auto& t = a.triangles[i];
        const Vec3& p1 = a.vertices[static_cast<std::size_t>(t[0])];
        const Vec3& q1 = a.vertices[static_cast<std::size_t>(t[1])];
        const Vec3& r1 = a.vertices[static_cast<std::size_t>(t[2])];
        for (std::size_t j = 0; j < moved.size(); ++j) {
            ++tests;
            const TriangleDistance td =
                distanceTriangleTriangle(p1, q1, r1, moved[j][0], moved[j][1], moved[j][2]);
            if (td.distance < out.distance) {
                out.distance = td.distance;
                out.a = static_cast<std::int32_t>(i);
                out.b = static_cast<std::int32_t>(j);
                out.point_on_a = td.point_on_1;
                out.point_on_b = td.point_on_2;
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return out;
}

std::vector<TrianglePair> intersectSelfBruteForce(const TriangleMesh& mesh, BvhQueryStats* stats) {
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    const std::size_t n = mesh.triangles.size();
    auto corner = [&](std::size_t t, int k) -> const Vec3& {
        return mesh
            .vertices[static_cast<std::size_t>(mesh.triangles[t][static_cast<std::size_t>(k)])];
    };
    std::vector<Vec3> lo(n);
    std::vector<Vec3> hi(n);
    for (std::size_t i = 0; i < n; ++i) {
        lo[i] = corner(i, 0).cwiseMin(corner(i, 1)).cwiseMin(corner(i, 2));
        hi[i] = corner(i, 0).cwiseMax(corner(i, 1)).cwiseMax(corner(i, 2));
    }
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
            // Disjoint exact boxes of the same coordinates: the triangles are apart.
            if ((lo[i].array() > hi[j].array()).any() || (lo[j].array() > hi[i].array()).any()) {
                continue;
            }
            if (shareVertex(mesh.triangles[i], mesh.triangles[j])) continue;
            ++tests;
            if (testTriangleTriangle(corner(i, 0), corner(i, 1), corner(i, 2), corner(j, 0),
                                     corner(j, 1), corner(j, 2))) {
                pairs.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return pairs;  // generated in (a, b) order
}

std::vector<TrianglePair> intersectMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                                      const Pose& b_in_a, BvhQueryStats* stats) {
    // The same transform as the BVH queries (scales do not matter: only `apply` is used).
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);
    struct Tri {
        Vec3 p, q, r, lo, hi;
    };
    auto make = [](const Vec3& p, const Vec3& q, const Vec3& r) {
        return Tri{p, q, r, p.cwiseMin(q).cwiseMin(r), p.cwiseMax(q).cwiseMax(r)};
    };
    std::vector<Tri> ta;
    std::vector<Tri> tb;
    for (const auto& t : a.triangles) {
        ta.push_back(make(a.vertices[static_cast<std::size_t>(t[0])],
                          a.vertices[static_cast<std::size_t>(t[1])],
                          a.vertices[static_cast<std::size_t>(t[2])]));
    }
    for (const auto& t : b.triangles) {
        tb.push_back(make(x.apply(b.vertices[static_cast<std::size_t>(t[0])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[1])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[2])])));
    }
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    for (std::size_t i = 0; i < ta.size(); ++i) {
        for (std::size_t j = 0; j < tb.size(); ++j) {
            // Disjoint exact (unrounded) boxes of the same coordinates: the triangles are apart.
            if ((ta[i].lo.array() > tb[j].hi.array()).any() ||
                (tb[j].lo.array() > ta[i].hi.array()).any()) {
                continue;
            }
            ++tests;
            if (testTriangleTriangle(ta[i].p, ta[i].q, ta[i].r, tb[j].p, tb[j].q, tb[j].r)) {
                pairs.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return pairs;  // generated in (a, b) order: sorted and unique
}

std::vector<TrianglePair> intersectMeshMeshSweep(const TriangleMesh& a, const TriangleMesh& b,
                                                 const Pose& b_in_a, BvhQueryStats* stats) {
    // The brute force's triangles and boxes (same transform, same expressions), but B's boxes
    // sorted by min.x: for A's triangle i only B's boxes with min.x in
    // [lo_i.x - widest B box, hi_i.x] can overlap, and those are tested with the brute force's
    // exact comparisons, so the candidate set and the answer are the brute force's.
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);
    struct Tri {
        Vec3 p, q, r, lo, hi;
        std::int32_t id;
    };
    auto make = [](const Vec3& p, const Vec3& q, const Vec3& r, std::size_t id) {
        return Tri{p,
                   q,
                   r,
                   p.cwiseMin(q).cwiseMin(r),
                   p.cwiseMax(q).cwiseMax(r),
                   static_cast<std::int32_t>(id)};
    };
    std::vector<Tri> ta;
    std::vector<Tri> tb;
    ta.reserve(a.triangles.size());
    tb.reserve(b.triangles.size());
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
        const auto& t = a.triangles[i];
        ta.push_back(make(a.vertices[static_cast<std::size_t>(t[0])],
                          a.vertices[static_cast<std::size_t>(t[1])],
                          a.vertices[static_cast<std::size_t>(t[2])], i));
    }
    Real widest = 0;
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
        const auto& t = b.triangles[j];
        tb.push_back(make(x.apply(b.vertices[static_cast<std::size_t>(t[0])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[1])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[2])]), j));
        widest = std::max(widest, tb.back().hi.x() - tb.back().lo.x());
    }
    std::sort(tb.begin(), tb.end(), [](const Tri& u, const Tri& v) {
        return u.lo.x() < v.lo.x() || (u.lo.x() == v.lo.x() && u.id < v.id);
    });
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    for (const Tri& ti : ta) {
        // Every box with lo.x >= ti.lo.x - widest, moved down by a rounding margin (only widens
        // the scan: the exact box test below decides).
        const Real from = ti.lo.x() - widest - Real(4) * kEpsilon * (std::abs(ti.lo.x()) + widest);
        auto it = std::lower_bound(tb.begin(), tb.end(), from,
                                   [](const Tri& u, Real v) { return u.lo.x() < v; });
        for (; it != tb.end() && it->lo.x() <= ti.hi.x(); ++it) {
            const Tri& tj = *it;
            if ((ti.lo.array() > tj.hi.array()).any() || (tj.lo.array() > ti.hi.array()).any()) {
                continue;
            }
            ++tests;
            if (testTriangleTriangle(ti.p, ti.q, ti.r, tj.p, tj.q, tj.r)) {
                pairs.push_back({ti.id, tj.id});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

}  // namespace collision

// collision/src/ccd/mesh.cpp -- time of impact of two moving triangle meshes: OBB-tree tandem
// traversal culled by the continuous OBB test, conservative advancement on the leaves.
// Invariant: slices of the step are searched in time order; when a slice is entered, no
// triangle pair came within target_gap in the earlier slices. Within a slice s_best only
// decreases, and a node pair is dropped only when testObbSweep proves its boxes apart on all of
// [0, s_best] of the slice, so no dropped pair could have come earlier.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "bvh/traversal.h"
#include "collision/bvh/bvh.h"
#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"

namespace collision {

namespace {

// A triangle as a flat convex shape (both windings, so the polytope is closed), in its mesh's
// local frame: timeOfImpact then bounds its motion with the mesh's sweep about the same origin.
Shape triangleShape(const std::array<Vec3, 3>& corners) {
    auto poly = std::make_shared<ConvexPolytope>();
    poly->vertices.assign(corners.begin(), corners.end());
    poly->faces = {{0, 1, 2}, {0, 2, 1}};
    return Shape::convexHull(std::move(poly));
}

}  // namespace

MeshToiOutput timeOfImpactMeshes(const MeshToiInput& input) {
    MeshToiOutput out;
    out.toi.state = CcdState::Failed;
    if (input.a == nullptr || input.b == nullptr) return out;
    const Bvh<Obb>& a = *input.a;
    const Bvh<Obb>& b = *input.b;
    Real t_best = std::clamp(input.t_max, Real(0), Real(1));
    out.toi.state = CcdState::Separated;
    out.toi.t = t_best;
    if (a.nodes().empty() || b.nodes().empty()) return out;

    // Triangle shapes are built once per leaf triangle that reaches a leaf pair.
    std::vector<std::unique_ptr<Shape>> shapes_a(static_cast<std::size_t>(a.triangleCount()));
    std::vector<std::unique_ptr<Shape>> shapes_b(static_cast<std::size_t>(b.triangleCount()));
    auto shapeOf = [](const Bvh<Obb>& tree, std::vector<std::unique_ptr<Shape>>& cache,
                      std::int32_t i) -> const Shape* {
        std::unique_ptr<Shape>& s = cache[static_cast<std::size_t>(i)];
        if (!s) s = std::make_unique<Shape>(triangleShape(tree.leafTriangle(i)));
        return s.get();
    };

    // The interval test is loose over a long, fast-turning step (its sin/cos enclosures widen
    // with the angle swept), so the step is cut into slices, searched in time order: each
    // slice gets its own traversal, and the first slice with a hit ends the search (no later
    // slice can hold an earlier contact). Slices are short enough that each body turns at most
    // kSliceAngle and moves at most a quarter of its root box's smallest half extent.
    constexpr Real kSliceAngle = Real(0.1);  // rad
    const Real turn = std::max(input.sweep_a.rotation.norm() + input.sweep_a.spin.norm(),
                               input.sweep_b.rotation.norm() + input.sweep_b.spin.norm());
    const Real size = std::min(a.nodes()[0].volume.half_extents.minCoeff(),
                               b.nodes()[0].volume.half_extents.minCoeff());
    const Real travel = (input.sweep_a.translation - input.sweep_b.translation).norm();
    const Real slices_wanted =
        std::max(turn / kSliceAngle, size > 0 ? travel / (size / 4) : Real(1));
    constexpr int kMaxSlices = 64;
    // Clamped before the cast: a flat mesh (root half extent ~1e-17) would ask for ~1e16.
    const int slices = slices_wanted <= Real(kMaxSlices)
                           ? std::max(1, static_cast<int>(std::ceil(slices_wanted)))
                           : kMaxSlices;

    std::vector<std::pair<std::int32_t, std::int32_t>> stack;
    const Real t_end = t_best;
    for (int k = 0; k < slices && out.toi.state == CcdState::Separated; ++k) {
        const Real t0 = t_end * k / slices;
        const Real t1 = k + 1 == slices ? t_end : t_end * (k + 1) / slices;
        // The sweeps restarted at t0 (same rates): pose at s is the original pose at t0 + s.
        Sweep sa = input.sweep_a;
        sa.start = input.sweep_a.at(t0);
        Sweep sb = input.sweep_b;
        sb.start = input.sweep_b.at(t0);
        Real s_best = t1 - t0;
        stack.assign(1, {0, 0});
        while (!stack.empty()) {
            const auto [ia, ib] = stack.back();
            stack.pop_back();
            const typename Bvh<Obb>::Node& na = a.nodes()[static_cast<std::size_t>(ia)];
            const typename Bvh<Obb>::Node& nb = b.nodes()[static_cast<std::size_t>(ib)];
            ++out.node_tests;
            // Redon et al. 2002: the 15 separating-axis inequalities on [0, s_best] of the slice.
            // A's box grown by the target gap on every axis holds every point within that gap
            // of the box, so a pair whose gap only closes to target_gap is not dropped.
            Obb box_a = na.volume;
            box_a.half_extents.array() += input.target_gap;
            if (!testObbSweep(box_a, sa, nb.volume, sb, 0, s_best)) continue;
            if (na.isLeaf() && nb.isLeaf()) {
                for (std::int32_t i = na.first; i < na.first + na.count; ++i) {
                    for (std::int32_t j = nb.first; j < nb.first + nb.count; ++j) {
                        ToiInput in;
                        static_cast<ToiQuery&>(in) = input;
                        in.a = shapeOf(a, shapes_a, i);
                        in.b = shapeOf(b, shapes_b, j);
                        in.sweep_a = sa;
                        in.sweep_b = sb;
                        in.t_max = s_best;
                        ++out.triangle_queries;
                        const ToiOutput r = timeOfImpact(in);
                        if (r.state == CcdState::Separated) continue;
                        // Hit, Overlapped or Failed (a safe time): the earliest one wins, a tie
                        // the smaller gap (the engine sizes its retry from it); Overlapped (only
                        // at the slice's start) always, and it ends the search.
                        if (r.state == CcdState::Overlapped || r.t < s_best ||
                            out.toi.state == CcdState::Separated ||
                            (r.t == s_best && r.distance < out.toi.distance)) {
                            s_best = r.t;
                            out.toi = r;
                            out.toi.t = t0 + r.t;
                            out.triangle_a = a.leafTriangleId(i);
                            out.triangle_b = b.leafTriangleId(j);
                        }
                        // At t = 0 Overlapped is the answer; later it means an earlier slice's
                        // advancement crossed by rounding: a Hit at the slice's start.
                        if (r.state == CcdState::Overlapped) {
                            if (t0 > 0) out.toi.state = CcdState::Hit;
                            return out;
                        }
                    }
                }
                continue;
            }
            // Descend the larger volume (or the only internal node), as the discrete traversal.
            pushChildrenOfLarger(stack, na, ia, nb, ib);
        }
    }
    return out;
}

}  // namespace collision

// collision/src/broadphase/cullide.cpp -- CULLIDE (Govindaraju, Redon, Lin, Manocha, "CULLIDE:
// Interactive Collision Detection Between Complex Models in Large Environments using Graphics
// Hardware", Graphics Hardware 2003), made conservative as in Govindaraju, Lin, Manocha, "Fast
// and Reliable Collision Culling using Graphics Hardware", VRST 2004.
//
// Invariant: a proxy leaves the potentially colliding set (PCS) only when its box, fattened by
// one pixel on screen and by kDepthPad in depth, is fully visible with respect to every other
// fattened box in one view (Lemma 1 of the 2003 paper: then it overlaps none of them). The
// pairs are then the exact closed AABB overlaps among the PCS, sorted by (a, b): the same set
// as `brute`, whatever the rasteriser misses.
//
// Why the fattening makes the pruning conservative: if two boxes overlap they share a point p.
// Fattened by a pixel's width on each side of u and v, both cover the centre of the pixel that
// holds p with half a pixel to spare, so both rasterise there. Along depth the far face of one
// lies at or behind the near face of the other; padded by kDepthPad (many depth-buffer steps and
// many float roundings of the normalised coordinates) the order survives rounding, so the
// GL_GEQUAL query counts a sample and the box stays in the PCS (the 2004 paper's Minkowski sum
// with the pixel). Coordinates are normalised in double around the scene's centre before they
// become float, so a scene far from the origin loses nothing to the projection.
#include "broadphase/cullide.h"

#include <algorithm>
#include <mutex>
#include <numeric>

#include "collision/assert.h"

namespace collision {

namespace {

// The scene's bounds map to [-kFill, kFill]; the margin keeps fattened boxes inside the view
// volume and leaves the cleared depth (the far plane) behind every box.
constexpr Real kFill = 0.875;
// 2^-16 of the depth range: 256 steps of a 24-bit depth buffer and far more than the float
// rounding (2^-24) of a coordinate in [-1, 1].
constexpr Real kDepthPad = Real(1) / Real(65536);

std::mutex& factoryMutex() {
    static std::mutex m;
    return m;
}
VisibilityOracleFactory& factory() {
    static VisibilityOracleFactory f;
    return f;
}

}  // namespace

void setVisibilityOracleFactory(VisibilityOracleFactory f) {
    std::lock_guard<std::mutex> lock(factoryMutex());
    factory() = std::move(f);
}

bool hasVisibilityOracleFactory() {
    std::lock_guard<std::mutex> lock(factoryMutex());
    return static_cast<bool>(factory());
}

namespace {

/// An oracle from the installed factory; throws BroadPhaseUnavailable when there is none.
std::unique_ptr<VisibilityOracle> installedOracle() {
    VisibilityOracleFactory f;
    {
        std::lock_guard<std::mutex> lock(factoryMutex());
        f = factory();
    }
    if (!f) {
        throw BroadPhaseUnavailable(
            "broad phase 'cullide' renders the bodies with OpenGL occlusion queries and needs the "
            "render module's OSMesa context; none was installed in this process");
    }
    return f();
}

}  // namespace

std::unique_ptr<BroadPhase> createCullide() {
    return std::make_unique<CullideBroadPhase>(installedOracle());
}

CullideBroadPhase::CullideBroadPhase(const CullideBroadPhase& other)
    : RebuildingBroadPhase(other),
      oracle_(installedOracle()),
      ids_(other.ids_),
      ndc_(other.ndc_),
      ordered_(other.ordered_),
      forward_(other.forward_),
      backward_(other.backward_),
      pcs_(other.pcs_) {}

std::unique_ptr<BroadPhase> CullideBroadPhase::clone() const {
    return std::unique_ptr<BroadPhase>(new CullideBroadPhase(*this));
}

CullideBroadPhase::CullideBroadPhase(std::unique_ptr<VisibilityOracle> oracle)
    : oracle_(std::move(oracle)) {
    if (!oracle_) throw BroadPhaseUnavailable("broad phase 'cullide': no visibility oracle");
}

void CullideBroadPhase::pruneAlong(int axis, std::vector<char>& pruned) {
    const std::size_t n = ndc_.size();
    // Pass 1 draws 0..n-1, pass 2 n-1..0: a box fully visible in both is fully visible with
    // respect to all others (CULLIDE 2003, §4.2).
    forward_.assign(n, 0);
    backward_.assign(n, 0);
    oracle_->fullyVisibleInOrder(ndc_, axis, forward_);
    ordered_.assign(ndc_.rbegin(), ndc_.rend());
    oracle_->fullyVisibleInOrder(ordered_, axis, backward_);
    for (std::size_t i = 0; i < n; ++i) {
        if (forward_[i] && backward_[n - 1 - i]) pruned[i] = 1;
    }
}

void CullideBroadPhase::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    pairs.clear();
    countMoves(counters);
    ids_.clear();
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (table_.contains(id)) ids_.push_back(id);
    }
    pcs_.clear();
    if (ids_.empty()) return;

    Aabb bounds = table_.aabb(ids_[0]);
    for (ProxyId id : ids_) {
        bounds.min = bounds.min.cwiseMin(table_.aabb(id).min);
        bounds.max = bounds.max.cwiseMax(table_.aabb(id).max);
    }
    const Vec3 centre = bounds.center();
    Vec3 half = bounds.extents() * Real(0.5);
    for (int k = 0; k < 3; ++k) {
        if (!(half[k] > 0)) half[k] = 1;  // a flat scene: any scale will do on that axis
    }
    // Bounds past what a double holds (extents of ~1e308) leave no view to render: nothing is
    // pruned and every proxy stays in the PCS.
    const bool can_render = half.allFinite() && centre.allFinite();
    const Real pixel = Real(2) / Real(oracle_->resolution());
    Vec3 pad = Vec3::Constant(pixel);
    ndc_.resize(ids_.size());
    std::vector<char> pruned(ids_.size(), 0);
    for (int axis = 0; can_render && axis < 3; ++axis) {
        // Fatten by a pixel on the screen axes and by kDepthPad along the view axis.
        pad = Vec3::Constant(pixel);
        pad[axis] = kDepthPad;
        for (std::size_t i = 0; i < ids_.size(); ++i) {
            const Aabb& b = table_.aabb(ids_[i]);
            ndc_[i].min = ((b.min - centre).cwiseQuotient(half) * kFill) - pad;
            ndc_[i].max = ((b.max - centre).cwiseQuotient(half) * kFill) + pad;
        }
        pruneAlong(axis, pruned);
    }
    for (std::size_t i = 0; i < ids_.size(); ++i) {
        if (!pruned[i]) pcs_.push_back(ids_[i]);
    }

    // Exact AABB pairs among the PCS: sort on min x, sweep, then sort the pairs.
    std::vector<ProxyId> order = pcs_;
    std::sort(order.begin(), order.end(), [&](ProxyId a, ProxyId b) {
        const Real xa = table_.aabb(a).min.x();
        const Real xb = table_.aabb(b).min.x();
        return xa < xb || (xa == xb && a < b);
    });
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Aabb& a = table_.aabb(order[i]);
        for (std::size_t j = i + 1; j < order.size(); ++j) {
            const Aabb& b = table_.aabb(order[j]);
            if (b.min.x() > a.max.x()) break;
            ++counters.volume_tests;
            if (a.overlaps(b)) {
                pairs.push_back(ProxyPair{std::min(order[i], order[j]),
                                          std::max(order[i], order[j])});
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

}  // namespace collision

// collision/src/broadphase/brute.cpp -- all-pairs references for AABBs, spheres and OBBs.
// Pairs come out sorted because the loops run over (a, b) in lexicographic order.
#include "broadphase/brute.h"

#include <cstdio>
#include <string>
#include <type_traits>

#include "collision/debug_draw.h"

namespace collision {

std::string_view BruteForceBroadPhase::name() const {
    switch (volume_) {
        case VolumeKind::Aabb: return "brute";
        case VolumeKind::Sphere: return "sphere-brute";
        case VolumeKind::Obb: return "obb-brute";
    }
    return "brute";
}

namespace {

// Every pair of the present proxies `ids` (increasing) tested with V::overlaps on the volumes
// `volume_of` gives, in lexicographic order. The volumes are packed first so the n^2 loop reads
// contiguous memory rather than the table's sparse arrays; the tests and their order are those
// of a loop over the table.
template <class VolumeOf>
void allPairs(const std::vector<ProxyId>& ids, VolumeOf volume_of, std::vector<ProxyPair>& pairs) {
    using V = std::decay_t<decltype(volume_of(ProxyId{}))>;
    std::vector<V> volumes;
    volumes.reserve(ids.size());
    for (ProxyId id : ids) volumes.push_back(volume_of(id));
    const std::size_t n = volumes.size();
    for (std::size_t i = 0; i < n; ++i) {
        const V& a = volumes[i];
        for (std::size_t j = i + 1; j < n; ++j) {
            if (a.overlaps(volumes[j])) pairs.push_back(ProxyPair{ids[i], ids[j]});
        }
    }
}

}  // namespace

void BruteForceBroadPhase::findPairs(std::vector<ProxyPair>& pairs,
                                     BroadPhaseCounters& counters) {
    pairs.clear();
    std::vector<ProxyId> ids;
    ids.reserve(static_cast<std::size_t>(table_.count()));
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (table_.contains(id)) ids.push_back(id);
    }
    switch (volume_) {
        case VolumeKind::Aabb:
            allPairs(ids, [this](ProxyId id) { return table_.aabb(id); }, pairs);
            break;
        case VolumeKind::Sphere:
            allPairs(ids, [this](ProxyId id) { return table_.sphere(id); }, pairs);
            break;
        case VolumeKind::Obb:
            allPairs(ids, [this](ProxyId id) { return table_.obb(id); }, pairs);
            break;
    }
    const auto m = static_cast<std::int64_t>(ids.size());
    counters.volume_tests += m * (m - 1) / 2;
    counters.volumes_updated += table_.count();
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void BruteForceBroadPhase::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    const long long n = table_.count();
    char label[128];
    std::snprintf(label, sizeof label,
                  "%s: no structure: every pair of its %lld proxies is tested (%lld pairs)",
                  std::string(name()).c_str(), n, n * (n - 1) / 2);
    draw.legend(label, kStructurePalette[0]);
}

}  // namespace collision

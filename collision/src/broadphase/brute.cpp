// collision/src/broadphase/brute.cpp -- all-pairs references for AABBs, spheres and OBBs.
// Pairs come out sorted because the loops run over (a, b) in lexicographic order.
#include "broadphase/brute.h"

namespace collision {

std::string_view BruteForceBroadPhase::name() const {
    switch (volume_) {
        case Volume::Aabb: return "brute";
        case Volume::Sphere: return "sphere-brute";
        case Volume::Obb: return "obb-brute";
    }
    return "brute";
}

namespace {

// Every pair of `volumes` (the present proxies' volumes, in increasing id order `ids`) tested
// with V::overlaps, in lexicographic order. The volumes are packed first so the n^2 loop reads
// contiguous memory rather than the table's sparse arrays; the tests and their order are those
// of a loop over the table.
template <class V>
void allPairs(const std::vector<ProxyId>& ids, const std::vector<V>& volumes,
              std::vector<ProxyPair>& pairs) {
    const std::size_t n = volumes.size();
    for (std::size_t i = 0; i < n; ++i) {
        const V& a = volumes[i];
        for (std::size_t j = i + 1; j < n; ++j) {
            if (a.overlaps(volumes[j])) pairs.push_back(ProxyPair{ids[i], ids[j]});
        }
    }
}

template <class V, class Get>
void packAndTest(const ProxyTable& table, Get get, std::vector<ProxyId>& ids,
                 std::vector<ProxyPair>& pairs) {
    std::vector<V> volumes;
    volumes.reserve(ids.size());
    for (ProxyId id : ids) volumes.push_back(get(table, id));
    allPairs(ids, volumes, pairs);
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
        case Volume::Aabb:
            packAndTest<Aabb>(
                table_, [](const ProxyTable& t, ProxyId id) { return t.aabb(id); }, ids, pairs);
            break;
        case Volume::Sphere:
            packAndTest<BoundingSphere>(
                table_, [](const ProxyTable& t, ProxyId id) { return t.sphere(id); }, ids, pairs);
            break;
        case Volume::Obb:
            packAndTest<Obb>(
                table_, [](const ProxyTable& t, ProxyId id) { return t.obb(id); }, ids, pairs);
            break;
    }
    const auto m = static_cast<std::int64_t>(ids.size());
    counters.volume_tests += m * (m - 1) / 2;
    counters.volumes_updated += table_.count();
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

}  // namespace collision

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

void BruteForceBroadPhase::findPairs(std::vector<ProxyPair>& pairs,
                                     BroadPhaseCounters& counters) {
    pairs.clear();
    const ProxyId n = table_.capacity();
    for (ProxyId a = 0; a < n; ++a) {
        if (!table_.contains(a)) continue;
        for (ProxyId b = a + 1; b < n; ++b) {
            if (!table_.contains(b)) continue;
            ++counters.volume_tests;
            bool hit = false;
            switch (volume_) {
                case Volume::Aabb: hit = table_.aabb(a).overlaps(table_.aabb(b)); break;
                case Volume::Sphere: hit = table_.sphere(a).overlaps(table_.sphere(b)); break;
                case Volume::Obb: hit = table_.obb(a).overlaps(table_.obb(b)); break;
            }
            if (hit) pairs.push_back(ProxyPair{a, b});
        }
    }
    counters.volumes_updated += table_.count();
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

}  // namespace collision

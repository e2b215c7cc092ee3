// collision/src/broad_phase_brute.cpp -- all-pairs references for AABBs, spheres and OBBs.
// Pairs come out sorted because the loops run over (a, b) in lexicographic order.
#include "broad_phase_brute.h"

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
        const ProxyVolumes& va = table_[a];
        for (ProxyId b = a + 1; b < n; ++b) {
            if (!table_.contains(b)) continue;
            const ProxyVolumes& vb = table_[b];
            ++counters.volume_tests;
            bool hit = false;
            switch (volume_) {
                case Volume::Aabb: hit = va.aabb.overlaps(vb.aabb); break;
                case Volume::Sphere: hit = va.sphere.overlaps(vb.sphere); break;
                case Volume::Obb: hit = va.obb.overlaps(vb.obb); break;
            }
            if (hit) pairs.push_back(ProxyPair{a, b});
        }
    }
    counters.volumes_updated += table_.count();
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

}  // namespace collision

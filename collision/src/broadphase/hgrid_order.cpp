// collision/src/broadphase/hgrid_order.cpp -- hgrid's per-frame order of the proxies by min x
// (the order the columns are scattered in) and the boxes gathered in it.
// Invariant: order_ holds every present proxy by (float(min x), id), box_[p] is order_[p]'s box.
#include "broadphase/hgrid.h"

#include <algorithm>
#include <cstdint>
#include <limits>

#include "broadphase/radix_sort.h"

namespace collision {

using radix::orderedBits;

bool HierarchicalGrid::resortByMinX() {
    // The same proxies as last frame: their keys in last frame's order, insertion-sorted as
    // whole 64-bit keys, i.e. by (key, id), the order the radix sort below gives. Coherent
    // motion leaves few keys out of place; past n / 2 shifts the sort is abandoned (boxes dense
    // along x: at 10k on the bench's workloads a box passes several others a frame, and the
    // insertion sort cost more than the radix sort) and not tried for kResortPause frames.
    // The keys are read in id order (the table is read in sequence, as by the radix sort) and
    // gathered in last frame's order from a 4-byte array: reading the table itself in that order
    // cost more than the sort saved from 10k boxes on.
    key_of_id_.resize(std::size_t(table_.capacity()));
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const float x = static_cast<float>(table_.aabb(id).min.x());
        key_of_id_[std::size_t(id)] = static_cast<std::uint32_t>(orderedBits(x));
    }
    const std::size_t n = order_.size();
    packed_.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        packed_[p] = std::uint64_t(key_of_id_[order_[p]]) << 32 | std::uint64_t(order_[p]);
    }
    std::uint64_t* const k = packed_.data();
    std::size_t shifts = 0;
    const std::size_t budget = n / 2 + 64;
    for (std::size_t i = 1; i < n; ++i) {
        const std::uint64_t moving = k[i];
        if (!(moving < k[i - 1])) continue;
        std::size_t j = i;
        do {
            k[j] = k[j - 1];
            --j;
        } while (j > 0 && moving < k[j - 1]);
        k[j] = moving;
        shifts += i - j;
        if (shifts > budget) {
            resort_pause_ = kResortPause;
            return false;
        }
    }
    for (std::size_t p = 0; p < n; ++p) order_[p] = static_cast<std::uint32_t>(k[p]);
    return true;
}

void HierarchicalGrid::sortByMinX() {
    if (resort_pause_ > 0) --resort_pause_;
    if (!order_stale_ && resort_pause_ == 0 && order_.size() == std::size_t(table_.count()) &&
        resortByMinX()) {
        return;
    }
    order_stale_ = false;
    // Keys: min x rounded to float (a non-decreasing map, so the order is exact up to ties of
    // the rounding, which fixColumns undoes), above the id; read in id order, sorted by the key
    // alone by a stable LSD radix sort, so ties stay in id order.
    packed_.clear();
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const float x = static_cast<float>(table_.aabb(id).min.x());
        packed_.push_back(orderedBits(x) << 32 | std::uint64_t(std::uint32_t(id)));
    }
    order_.resize(packed_.size());
    radix::lsdRadixSort(packed_, packed_scratch_, 32, 32, [this](std::size_t p, std::uint64_t key) {
        order_[p] = static_cast<std::uint32_t>(key);
    });
}

HierarchicalGrid::Extents HierarchicalGrid::gatherBoxes() {
    // The boxes in sorted order, with their largest extent and bounds.
    Extents x;
    x.lo_y = x.lo_z = std::numeric_limits<Real>::max();
    x.hi_y = x.hi_z = std::numeric_limits<Real>::lowest();
    x.lo_c = Vec3::Constant(std::numeric_limits<Real>::max());
    x.hi_c = Vec3::Constant(std::numeric_limits<Real>::lowest());
    box_.resize(order_.size());
    for (std::size_t p = 0; p < order_.size(); ++p) {
        const Aabb& b = box_[p] = table_.aabb(ProxyId(order_[p]));
        x.top = std::max(x.top, extentOf(b));
        const Vec3 c = (b.min + b.max) / 2;  // centres: where the boxes are, for planLevels
        x.lo_c = x.lo_c.cwiseMin(c);
        x.hi_c = x.hi_c.cwiseMax(c);
        x.lo_y = std::min(x.lo_y, b.min.y());
        x.hi_y = std::max(x.hi_y, b.max.y());
        x.lo_z = std::min(x.lo_z, b.min.z());
        x.hi_z = std::max(x.hi_z, b.max.z());
    }
    if (!(x.top > 0)) x.top = 1;
    return x;
}

}  // namespace collision

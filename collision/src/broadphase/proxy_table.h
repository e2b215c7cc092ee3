// collision/src/broadphase/proxy_table.h -- id -> volumes storage shared by the broad phases.
// Ids index dense vectors; absent slots are marked, so ids may be reused after removal. A table
// keeps only the volume kinds its broad phase reads (an AABB broad phase copies 48 bytes per
// move, not the 200 of all three volumes), each kind in its own array.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "collision/assert.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

class ProxyTable {
public:
    enum Kinds : std::uint8_t { kAabb = 1, kSphere = 2, kObb = 4, kAll = 7 };
    explicit ProxyTable(std::uint8_t kinds = kAabb) : kinds_(kinds) {}

    void insert(ProxyId id, const ProxyVolumes& v) {
        CDLAB_ASSERT(id >= 0, "negative proxy id");
        if (static_cast<std::size_t>(id) >= present_.size()) {
            const std::size_t n = static_cast<std::size_t>(id) + 1;
            present_.resize(n, 0);
            if (kinds_ & kAabb) aabbs_.resize(n);
            if (kinds_ & kSphere) spheres_.resize(n);
            if (kinds_ & kObb) obbs_.resize(n);
        }
        CDLAB_ASSERT(!present_[id], "proxy inserted twice");
        store(id, v);
        present_[id] = 1;
        ++count_;
    }
    /// insert() of ids first, first + 1, ... with the storage grown once.
    void insertMany(ProxyId first, std::span<const ProxyVolumes> v) {
        CDLAB_ASSERT(first >= 0, "negative proxy id");
        const std::size_t begin = static_cast<std::size_t>(first);
        const std::size_t end = begin + v.size();
        if (end > present_.size()) {
            present_.resize(end, 0);
            if (kinds_ & kAabb) aabbs_.resize(end);
            if (kinds_ & kSphere) spheres_.resize(end);
            if (kinds_ & kObb) obbs_.resize(end);
        }
        for (std::size_t i = begin; i < end; ++i) CDLAB_ASSERT(!present_[i], "proxy inserted twice");
        // One loop per kind: the caller's volumes are read at their stride, the table written in
        // sequence.
        if (kinds_ & kAabb) {
            for (std::size_t i = 0; i < v.size(); ++i) aabbs_[begin + i] = v[i].aabb;
        }
        if (kinds_ & kSphere) {
            for (std::size_t i = 0; i < v.size(); ++i) spheres_[begin + i] = v[i].sphere;
        }
        if (kinds_ & kObb) {
            for (std::size_t i = 0; i < v.size(); ++i) obbs_[begin + i] = v[i].obb;
        }
        std::fill(present_.begin() + std::ptrdiff_t(begin), present_.begin() + std::ptrdiff_t(end),
                  char(1));
        count_ += static_cast<int>(v.size());
    }
    void remove(ProxyId id) {
        CDLAB_ASSERT(contains(id), "removing an absent proxy");
        present_[id] = 0;
        --count_;
    }
    void move(ProxyId id, const ProxyVolumes& v) {
        CDLAB_ASSERT(contains(id), "moving an absent proxy");
        store(id, v);
    }
    bool contains(ProxyId id) const {
        return id >= 0 && static_cast<std::size_t>(id) < present_.size() && present_[id];
    }
    const Aabb& aabb(ProxyId id) const { return aabbs_[id]; }
    const BoundingSphere& sphere(ProxyId id) const { return spheres_[id]; }
    const Obb& obb(ProxyId id) const { return obbs_[id]; }
    ProxyId capacity() const { return static_cast<ProxyId>(present_.size()); }
    int count() const { return count_; }

private:
    void store(ProxyId id, const ProxyVolumes& v) {
        if (kinds_ & kAabb) aabbs_[id] = v.aabb;
        if (kinds_ & kSphere) spheres_[id] = v.sphere;
        if (kinds_ & kObb) obbs_[id] = v.obb;
    }

    std::uint8_t kinds_;
    std::vector<Aabb> aabbs_;
    std::vector<BoundingSphere> spheres_;
    std::vector<Obb> obbs_;
    std::vector<char> present_;
    int count_ = 0;
};

/// A broad phase rebuilt from its ProxyTable in every findPairs (grid, hash, hgrid, octree,
/// sphere, obb): insert, remove and move only update the table, and a move is counted for
/// BroadPhaseCounters::volumes_updated.
class RebuildingBroadPhase : public BroadPhase {
public:
    explicit RebuildingBroadPhase(std::uint8_t kinds = ProxyTable::kAabb) : table_(kinds) {}

    void insert(ProxyId id, const ProxyVolumes& v) override { table_.insert(id, v); }
    void insertMany(ProxyId first, std::span<const ProxyVolumes> v) override {
        table_.insertMany(first, v);
    }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) override {
        table_.move(id, v);
        ++moved_;
    }

protected:
    /// Adds the moves since the last call to `counters`; called once per findPairs.
    void countMoves(BroadPhaseCounters& counters) {
        counters.volumes_updated += moved_;
        moved_ = 0;
    }

    ProxyTable table_;

private:
    std::int64_t moved_ = 0;
};

}  // namespace collision

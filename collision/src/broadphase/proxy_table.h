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
        const std::size_t begin = makeRoom(first, v.size());
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
        markPresent(begin, v.size());
    }
    /// insertMany() of volumesOfBox(boxes[i]): the boxes copied as they are, the other kinds
    /// the table keeps derived from them.
    void insertBoxes(ProxyId first, std::span<const Aabb> boxes) {
        const std::size_t begin = makeRoom(first, boxes.size());
        if (kinds_ == kAabb) {
            std::copy(boxes.begin(), boxes.end(), aabbs_.begin() + std::ptrdiff_t(begin));
        } else {
            for (std::size_t i = 0; i < boxes.size(); ++i) store(begin + i, volumesOfBox(boxes[i]));
        }
        markPresent(begin, boxes.size());
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
    /// move() to volumesOfBox(box).
    void moveBox(ProxyId id, const Aabb& box) {
        CDLAB_ASSERT(contains(id), "moving an absent proxy");
        if (kinds_ == kAabb) {
            aabbs_[id] = box;
        } else {
            store(id, volumesOfBox(box));
        }
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
    /// Grows the storage to hold ids first, first + 1, ..., first + n - 1, which must be absent;
    /// returns first as an index.
    std::size_t makeRoom(ProxyId first, std::size_t n) {
        CDLAB_ASSERT(first >= 0, "negative proxy id");
        const std::size_t begin = static_cast<std::size_t>(first);
        const std::size_t end = begin + n;
        if (end > present_.size()) {
            present_.resize(end, 0);
            if (kinds_ & kAabb) aabbs_.resize(end);
            if (kinds_ & kSphere) spheres_.resize(end);
            if (kinds_ & kObb) obbs_.resize(end);
        }
        for (std::size_t i = begin; i < end; ++i) CDLAB_ASSERT(!present_[i], "proxy inserted twice");
        return begin;
    }
    void markPresent(std::size_t begin, std::size_t n) {
        std::fill_n(present_.begin() + std::ptrdiff_t(begin), n, char(1));
        count_ += static_cast<int>(n);
    }
    void store(std::size_t id, const ProxyVolumes& v) {
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
    void insertBoxes(ProxyId first, std::span<const Aabb> boxes) override {
        table_.insertBoxes(first, boxes);
    }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) final {
        table_.move(id, v);
        ++moved_;
    }
    void moveBoxes(ProxyId first, std::span<const Aabb> boxes) final {
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            table_.moveBox(first + static_cast<ProxyId>(i), boxes[i]);
        }
        moved_ += static_cast<std::int64_t>(boxes.size());
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

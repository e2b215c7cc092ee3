// collision/src/proxy_table.h -- id -> volumes storage shared by the broad phases.
// Ids index a dense vector; absent slots are marked, so ids may be reused after removal.
#pragma once

#include <vector>

#include "collision/assert.h"
#include "collision/broad_phase.h"

namespace collision {

class ProxyTable {
public:
    void insert(ProxyId id, const ProxyVolumes& v) {
        CDLAB_ASSERT(id >= 0, "negative proxy id");
        if (static_cast<std::size_t>(id) >= volumes_.size()) {
            volumes_.resize(id + 1);
            present_.resize(id + 1, 0);
        }
        CDLAB_ASSERT(!present_[id], "proxy inserted twice");
        volumes_[id] = v;
        present_[id] = 1;
        ++count_;
    }
    void remove(ProxyId id) {
        CDLAB_ASSERT(contains(id), "removing an absent proxy");
        present_[id] = 0;
        --count_;
    }
    void move(ProxyId id, const ProxyVolumes& v) {
        CDLAB_ASSERT(contains(id), "moving an absent proxy");
        volumes_[id] = v;
    }
    bool contains(ProxyId id) const {
        return id >= 0 && static_cast<std::size_t>(id) < present_.size() && present_[id];
    }
    const ProxyVolumes& operator[](ProxyId id) const { return volumes_[id]; }
    ProxyId capacity() const { return static_cast<ProxyId>(volumes_.size()); }
    int count() const { return count_; }

private:
    std::vector<ProxyVolumes> volumes_;
    std::vector<char> present_;
    int count_ = 0;
};

}  // namespace collision

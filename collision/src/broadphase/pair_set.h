// collision/src/broadphase/pair_set.h -- a flat hash set of packed pair keys (private to the broad
// phases): sweep-and-prune adds and removes a pair on every crossing endpoint, so the set must be
// cheap to update and to walk. Open addressing, linear probing, backward-shift deletion (Knuth
// TAOCP 3 §6.4 Algorithm R): no tombstones, so the table never degrades under churn.
#pragma once

#include <cstdint>
#include <vector>

namespace collision {

/// Set of 64-bit keys other than kEmpty. Iteration order depends on the hash; callers sort.
class PairSet {
public:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);

    void clear() { reset(slots_.empty() ? 64 : slots_.size()); }
    std::size_t size() const { return size_; }

    void insert(std::uint64_t key) {
        if (2 * (size_ + 1) > slots_.size()) grow();
        std::size_t i = home(key);
        while (slots_[i] != kEmpty) {
            if (slots_[i] == key) return;
            i = (i + 1) & mask_;
        }
        slots_[i] = key;
        ++size_;
    }

    void erase(std::uint64_t key) {
        if (slots_.empty()) return;
        std::size_t i = home(key);
        while (slots_[i] != key) {
            if (slots_[i] == kEmpty) return;
            i = (i + 1) & mask_;
        }
        // Shift later members of the probe run back into the hole when their home slot does
        // not lie cyclically in (hole, their slot].
        std::size_t j = i;
        for (;;) {
            j = (j + 1) & mask_;
            if (slots_[j] == kEmpty) break;
            const std::size_t k = home(slots_[j]);
            const bool stays = i <= j ? (i < k && k <= j) : (i < k || k <= j);
            if (!stays) {
                slots_[i] = slots_[j];
                i = j;
            }
        }
        slots_[i] = kEmpty;
        --size_;
    }

    /// Calls f(key) for every member.
    template <class F>
    void forEach(F&& f) const {
        for (std::uint64_t k : slots_) {
            if (k != kEmpty) f(k);
        }
    }

private:
    std::size_t home(std::uint64_t key) const {
        return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
    }
    // `capacity` a power of two >= 2.
    void reset(std::size_t capacity) {
        slots_.assign(capacity, kEmpty);
        mask_ = capacity - 1;
        shift_ = 64;
        for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
        size_ = 0;
    }
    void grow() {
        std::vector<std::uint64_t> old;
        old.swap(slots_);
        reset(old.empty() ? 64 : 2 * old.size());
        for (std::uint64_t k : old) {
            if (k != kEmpty) insert(k);
        }
    }

    std::vector<std::uint64_t> slots_;
    std::size_t mask_ = 0;
    int shift_ = 58;
    std::size_t size_ = 0;
};

}  // namespace collision

// collision/src/radix_sort.h -- LSD radix sorts shared by the broad phases (private): sorting
// packed pair keys and coordinate keys in O(n) passes instead of O(n log n) comparisons.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "collision/broad_phase.h"

namespace collision::radix {

inline constexpr int kDigitBits = 11;
inline constexpr std::size_t kBuckets = std::size_t(1) << kDigitBits;

// Order-preserving map of a coordinate to an unsigned integer (-0 and +0 map alike).
template <typename T>
inline std::uint64_t orderedBits(T v) {
    if (v == 0) v = 0;
    using U = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
    constexpr int kTop = int(sizeof(T)) * 8 - 1;
    const U b = std::bit_cast<U>(v);
    return (b >> kTop) ? U(~b) : U(b | (U(1) << kTop));
}

// LSD radix sort of 64-bit keys, 11 bits per pass, skipping digits that are all equal; stable.
inline void radixSortKeys(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch,
                   int bits) {
    scratch.resize(keys.size());
    std::array<std::uint32_t, kBuckets> count;
    for (int shift = 0; shift < bits; shift += kDigitBits) {
        count.fill(0);
        for (std::uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
        if (count[(keys[0] >> shift) & (kBuckets - 1)] == keys.size()) continue;
        std::uint32_t sum = 0;
        for (std::uint32_t& c : count) {
            const std::uint32_t here = c;
            c = sum;
            sum += here;
        }
        for (std::uint64_t k : keys) scratch[count[(k >> shift) & (kBuckets - 1)]++] = k;
        keys.swap(scratch);
    }
}

// Stable LSD radix sort of `order` (indices) by key[index].
inline void radixSortIndices(std::vector<std::uint32_t>& order, std::vector<std::uint32_t>& scratch,
                      const std::vector<std::uint64_t>& key) {
    scratch.resize(order.size());
    std::array<std::uint32_t, kBuckets> count;
    for (int shift = 0; shift < 64; shift += kDigitBits) {
        count.fill(0);
        for (std::uint32_t i : order) ++count[(key[i] >> shift) & (kBuckets - 1)];
        if (count[(key[order[0]] >> shift) & (kBuckets - 1)] == order.size()) continue;
        std::uint32_t sum = 0;
        for (std::uint32_t& c : count) {
            const std::uint32_t here = c;
            c = sum;
            sum += here;
        }
        for (std::uint32_t i : order) scratch[count[(key[i] >> shift) & (kBuckets - 1)]++] = i;
        order.swap(scratch);
    }
}

inline int bitsFor(std::uint64_t n) {
    int b = 1;
    while ((std::uint64_t(1) << b) < n) ++b;
    return b;
}

/// Sorts `keys` (each (a << shift) | b, a < b < 2^shift) and writes them to `pairs` as (a, b):
/// the sorted, unique pair list every broad phase returns. `scratch` is reused storage.
inline void keysToSortedPairs(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch,
                              int shift, std::vector<ProxyPair>& pairs) {
    if (keys.size() > 64) {
        radixSortKeys(keys, scratch, 2 * shift);
    } else {
        std::sort(keys.begin(), keys.end());
    }
    pairs.resize(keys.size());
    const std::uint64_t mask = (std::uint64_t(1) << shift) - 1;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        pairs[i] = ProxyPair{static_cast<ProxyId>(keys[i] >> shift),
                             static_cast<ProxyId>(keys[i] & mask)};
    }
}

}  // namespace collision::radix

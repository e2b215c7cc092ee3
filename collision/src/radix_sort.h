// collision/src/radix_sort.h -- LSD radix sorts shared by the broad phases (private): sorting
// packed pair keys and coordinate keys in O(n) passes instead of O(n log n) comparisons.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <span>
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

// Stable LSD radix sort of 64-bit values by their upper 32 bits (11 + 11 + 10 bits, all
// histograms in one read; a digit equal in every value costs no pass).
inline void radixSortHigh32(std::vector<std::uint64_t>& values,
                            std::vector<std::uint64_t>& scratch) {
    constexpr int kShifts[3] = {32, 43, 54};
    constexpr std::size_t kSize = std::size_t(1) << 11;
    const std::size_t n = values.size();
    if (n < 2) return;
    std::array<std::array<std::uint32_t, kSize>, 3> count{};
    for (std::uint64_t v : values) {
        for (int d = 0; d < 3; ++d) ++count[d][(v >> kShifts[d]) & (kSize - 1)];
    }
    scratch.resize(n);
    for (int d = 0; d < 3; ++d) {
        std::array<std::uint32_t, kSize>& c = count[d];
        const int shift = kShifts[d];
        if (c[(values[0] >> shift) & (kSize - 1)] == n) continue;
        std::uint32_t sum = 0;
        for (std::uint32_t& slot : c) {
            const std::uint32_t here = slot;
            slot = sum;
            sum += here;
        }
        for (std::uint64_t v : values) scratch[c[(v >> shift) & (kSize - 1)]++] = v;
        values.swap(scratch);
    }
}

inline int bitsFor(std::uint64_t n) {
    int b = 1;
    while ((std::uint64_t(1) << b) < n) ++b;
    return b;
}

/// Sorts `keys` (each (a << shift) | b, a < b < 2^shift) and writes them to `pairs` as (a, b):
/// the sorted, unique pair list every broad phase returns. `scratch` is reused storage; `keys`
/// is left in an unspecified order. An LSD radix sort: the digits are as few as possible of at
/// most 14 bits (a 64 KiB histogram), all counted in one read pass; a digit that is the same in
/// every key costs no pass, and the last pass writes the pairs themselves.
/// With `order_ids` the keys may hold their two ids either way round ((b << shift) | a); they
/// are put as (a, b) in the counting pass, so a caller need not order them per candidate.
inline void keysToSortedPairs(std::span<std::uint64_t> keys, std::vector<std::uint64_t>& scratch,
                              int shift, std::vector<ProxyPair>& pairs, bool order_ids = false) {
    const std::size_t n = keys.size();
    pairs.resize(n);
    const std::uint64_t id_mask = (std::uint64_t(1) << shift) - 1;
    const auto toPair = [shift, id_mask](std::uint64_t k) {
        return ProxyPair{static_cast<ProxyId>(k >> shift), static_cast<ProxyId>(k & id_mask)};
    };
    if (order_ids) {
        for (std::uint64_t& k : keys) {
            const std::uint64_t x = k >> shift, y = k & id_mask;
            const std::uint64_t swap = (x ^ y) & (std::uint64_t(0) - std::uint64_t(x > y));
            k = ((x ^ swap) << shift) | (y ^ swap);  // (min, max) by masks: no branch
        }
    }
    if (n <= 64) {
        std::sort(keys.begin(), keys.end());
        for (std::size_t i = 0; i < n; ++i) pairs[i] = toPair(keys[i]);
        return;
    }
    constexpr int kMaxDigitBits = 14;
    constexpr int kMaxDigits = (64 + kMaxDigitBits - 1) / kMaxDigitBits;
    const int bits = std::clamp(2 * shift, 1, 64);
    const int digits = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
    const int width = (bits + digits - 1) / digits;
    const std::size_t buckets = std::size_t(1) << width;
    const std::uint64_t mask = buckets - 1;
    thread_local std::vector<std::uint32_t> histogram;  // reused: no allocation once grown
    histogram.assign(buckets * std::size_t(digits), 0);
    std::array<std::uint32_t*, kMaxDigits> count{};
    for (int d = 0; d < digits; ++d) count[d] = histogram.data() + buckets * std::size_t(d);
    for (std::uint64_t k : keys) {
        for (int d = 0; d < digits; ++d) ++count[d][(k >> (d * width)) & mask];
    }
    std::array<int, kMaxDigits> passes{};
    int pass_count = 0;
    for (int d = 0; d < digits; ++d) {
        if (count[d][(keys[0] >> (d * width)) & mask] != n) passes[pass_count++] = d;
    }
    scratch.resize(n);
    std::uint64_t* from = keys.data();
    std::uint64_t* to = scratch.data();
    for (int p = 0; p < pass_count; ++p) {
        const int d = passes[p];
        std::uint32_t* const c = count[d];
        std::uint32_t sum = 0;
        for (std::size_t i = 0; i < buckets; ++i) {
            const std::uint32_t here = c[i];
            c[i] = sum;
            sum += here;
        }
        const int digit_shift = d * width;
        if (p + 1 == pass_count) {
            for (std::size_t i = 0; i < n; ++i) {
                const std::uint64_t k = from[i];
                pairs[c[(k >> digit_shift) & mask]++] = toPair(k);
            }
            return;
        }
        for (std::size_t i = 0; i < n; ++i) {
            const std::uint64_t k = from[i];
            to[c[(k >> digit_shift) & mask]++] = k;
        }
        std::swap(from, to);
    }
    for (std::size_t i = 0; i < n; ++i) pairs[i] = toPair(from[i]);  // one key, or all equal
}

}  // namespace collision::radix

// collision/src/broadphase/radix_sort.h -- LSD radix sorts shared by the broad phases (private):
// sorting packed pair keys and coordinate keys in O(n) passes instead of O(n log n) comparisons.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "collision/broadphase/broad_phase.h"

namespace collision::radix {

// Order-preserving map of a coordinate to an unsigned integer (-0 and +0 map alike).
template <typename T>
inline std::uint64_t orderedBits(T v) {
    if (v == 0) v = 0;
    using U = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
    constexpr int kTop = int(sizeof(T)) * 8 - 1;
    const U b = std::bit_cast<U>(v);
    return (b >> kTop) ? U(~b) : U(b | (U(1) << kTop));
}

// Stable LSD radix sort of `keys` by their bits [low, low + bits): as few digits as possible of
// at most 14 bits (a 64 KiB histogram), all counted in one read pass; a digit that is the same
// in every key costs no pass. The last pass does not store the keys: it calls emit(i, key) for
// every key, i being its place in sorted order, so a caller writes what it needs (pairs, ids)
// straight from it. `keys` is left in an unspecified order; `scratch` is reused storage.
template <typename Emit>
void lsdRadixSort(std::span<std::uint64_t> keys, std::vector<std::uint64_t>& scratch, int low,
                  int bits, Emit&& emit) {
    constexpr int kMaxDigitBits = 14;
    constexpr int kMaxDigits = (64 + kMaxDigitBits - 1) / kMaxDigitBits;
    const std::size_t n = keys.size();
    bits = std::clamp(bits, 1, 64 - low);
    const int digits = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
    const int width = (bits + digits - 1) / digits;
    const std::size_t buckets = std::size_t(1) << width;
    const std::uint64_t mask = buckets - 1;
    thread_local std::vector<std::uint32_t> histogram;  // reused: no allocation once grown
    histogram.assign(buckets * std::size_t(digits), 0);
    std::array<std::uint32_t*, kMaxDigits> count{};
    for (int d = 0; d < digits; ++d) count[d] = histogram.data() + buckets * std::size_t(d);
    for (std::uint64_t k : keys) {
        for (int d = 0; d < digits; ++d) ++count[d][(k >> (low + d * width)) & mask];
    }
    std::array<int, kMaxDigits> passes{};
    int pass_count = 0;
    for (int d = 0; d < digits && n > 0; ++d) {
        if (count[d][(keys[0] >> (low + d * width)) & mask] != n) passes[pass_count++] = d;
    }
    scratch.resize(n);
    std::uint64_t* from = keys.data();
    std::uint64_t* to = scratch.data();
    for (int p = 0; p < pass_count; ++p) {
        std::uint32_t* const c = count[passes[p]];
        std::uint32_t sum = 0;
        for (std::size_t i = 0; i < buckets; ++i) {
            const std::uint32_t here = c[i];
            c[i] = sum;
            sum += here;
        }
        const int digit_shift = low + passes[p] * width;
        if (p + 1 == pass_count) {
            for (std::size_t i = 0; i < n; ++i) {
                const std::uint64_t k = from[i];
                emit(std::size_t(c[(k >> digit_shift) & mask]++), k);
            }
            return;
        }
        for (std::size_t i = 0; i < n; ++i) {
            const std::uint64_t k = from[i];
            to[c[(k >> digit_shift) & mask]++] = k;
        }
        std::swap(from, to);
    }
    for (std::size_t i = 0; i < n; ++i) emit(i, from[i]);  // already in order
}

inline int bitsFor(std::uint64_t n) {
    int b = 1;
    while ((std::uint64_t(1) << b) < n) ++b;
    return b;
}

/// Sorts `keys` (each (a << shift) | b, a < b < 2^shift) and writes them to `pairs` as (a, b):
/// the sorted, unique pair list every broad phase returns. `scratch` is reused storage; `keys`
/// is left in an unspecified order. lsdRadixSort's last pass writes the pairs themselves.
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
    lsdRadixSort(keys, scratch, 0, 2 * shift,
                 [&](std::size_t i, std::uint64_t k) { pairs[i] = toPair(k); });
}

/// Writes `keys` (each (a << shift) | b or (b << shift) | a) to `pairs` as (a, b), a < b, in
/// the keys' order: keysToSortedPairs without the sort.
inline void keysToPairs(std::span<const std::uint64_t> keys, int shift,
                        std::vector<ProxyPair>& pairs) {
    const std::uint64_t id_mask = (std::uint64_t(1) << shift) - 1;
    pairs.resize(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
        const auto x = static_cast<ProxyId>(keys[i] >> shift);
        const auto y = static_cast<ProxyId>(keys[i] & id_mask);
        pairs[i] = ProxyPair{std::min(x, y), std::max(x, y)};
    }
}

}  // namespace collision::radix

// collision/src/broadphase/radix_sort.h -- LSD radix sorts shared by the broad phases (private):
// sorting packed pair keys and coordinate keys in O(n) passes instead of O(n log n) comparisons.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "collision/broadphase/broad_phase.h"

namespace collision::radix {

// Order-preserving map of a coordinate to an unsigned integer (-0 and +0 map alike): a negative
// value's bits all flipped, a non-negative one's sign bit set. The flip is a mask, not a branch:
// the sign is data (half the keys of a scene around the origin), and a branch on it was
// mispredicted about every other key.
template <typename T>
inline std::uint64_t orderedBits(T v) {
    if (v == 0) v = 0;
    using U = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
    constexpr int kTop = int(sizeof(T)) * 8 - 1;
    const U b = std::bit_cast<U>(v);
    return U(b ^ (U(U(0) - (b >> kTop)) | (U(1) << kTop)));
}

// Stable LSD radix sort of n keys by their bits [low, low + bits): as few digits as possible of
// at most 14 bits (a 64 KiB histogram), all counted in one pass that also writes the keys, from
// load(i), into `keys` (so a caller can convert them on the way: order a pair's ids, narrow
// them to 32 bits); a digit that is the same in every key costs no pass. The last pass does not
// store the keys: it calls emit(i, key) for every key, i being its place in sorted order, so a
// caller writes what it needs (pairs, ids) straight from it. `keys` and `scratch` hold n keys
// each and are left in an unspecified order.
template <typename Key, typename Load, typename Emit>
void lsdRadixSortLoaded(std::size_t n, Load&& load, Key* keys, Key* scratch, int low, int bits,
                        Emit&& emit) {
    constexpr int kMaxDigitBits = 14;
    constexpr int kKeyBits = int(sizeof(Key)) * 8;
    constexpr int kMaxDigits = (kKeyBits + kMaxDigitBits - 1) / kMaxDigitBits;
    bits = std::clamp(bits, 1, kKeyBits - low);
    const int digits = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
    const int width = (bits + digits - 1) / digits;
    const std::size_t buckets = std::size_t(1) << width;
    const Key mask = Key(buckets - 1);
    thread_local std::vector<std::uint32_t> histogram;  // reused: no allocation once grown
    histogram.assign(buckets * std::size_t(digits), 0);
    std::array<std::uint32_t*, kMaxDigits> count{};
    for (int d = 0; d < digits; ++d) count[d] = histogram.data() + buckets * std::size_t(d);
    for (std::size_t i = 0; i < n; ++i) {
        const Key k = load(i);
        keys[i] = k;
        for (int d = 0; d < digits; ++d) ++count[d][(k >> (low + d * width)) & mask];
    }
    std::array<int, kMaxDigits> passes{};
    int pass_count = 0;
    for (int d = 0; d < digits && n > 0; ++d) {
        if (count[d][(keys[0] >> (low + d * width)) & mask] != n) passes[pass_count++] = d;
    }
    Key* from = keys;
    Key* to = scratch;
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
                const Key k = from[i];
                emit(std::size_t(c[(k >> digit_shift) & mask]++), k);
            }
            return;
        }
        for (std::size_t i = 0; i < n; ++i) {
            const Key k = from[i];
            to[c[(k >> digit_shift) & mask]++] = k;
        }
        std::swap(from, to);
    }
    for (std::size_t i = 0; i < n; ++i) emit(i, from[i]);  // already in order
}

// lsdRadixSort of `keys` as they are. `scratch` is reused storage.
template <typename Emit>
void lsdRadixSort(std::span<std::uint64_t> keys, std::vector<std::uint64_t>& scratch, int low,
                  int bits, Emit&& emit) {
    scratch.resize(keys.size());
    std::uint64_t* const k = keys.data();
    lsdRadixSortLoaded(
        keys.size(), [k](std::size_t i) { return k[i]; }, k, scratch.data(), low, bits,
        std::forward<Emit>(emit));
}

inline int bitsFor(std::uint64_t n) {
    int b = 1;
    while ((std::uint64_t(1) << b) < n) ++b;
    return b;
}

/// Sorts `keys` (each (a << shift) | b, a < b < 2^shift) and writes them to `pairs` as (a, b):
/// the sorted, unique pair list every broad phase returns. `scratch` is reused storage; `keys`
/// is left in an unspecified order. With `order_ids` the keys may hold their two ids either way
/// round ((b << shift) | a); they are put as (a, b) in the counting pass, so a caller need not
/// order them per candidate. Keys of at most 32 bits (up to 65,536 ids) are sorted as 32-bit
/// integers, half the memory traffic of every pass; lsdRadixSort's last pass writes the pairs.
inline void keysToSortedPairs(std::span<std::uint64_t> keys, std::vector<std::uint64_t>& scratch,
                              int shift, std::vector<ProxyPair>& pairs, bool order_ids = false) {
    const std::size_t n = keys.size();
    pairs.resize(n);
    const std::uint64_t id_mask = (std::uint64_t(1) << shift) - 1;
    const std::uint64_t* const in = keys.data();
    const auto load = [in, shift, id_mask, order_ids](std::size_t i) {
        const std::uint64_t k = in[i];
        if (!order_ids) return k;
        const std::uint64_t x = k >> shift, y = k & id_mask;
        const std::uint64_t swap = (x ^ y) & (std::uint64_t(0) - std::uint64_t(x > y));
        return ((x ^ swap) << shift) | (y ^ swap);  // (min, max) by masks: no branch
    };
    ProxyPair* const out = pairs.data();
    const auto emit = [out, shift, id_mask](std::size_t i, auto k) {
        out[i] = ProxyPair{static_cast<ProxyId>(k >> shift), static_cast<ProxyId>(k & id_mask)};
    };
    if (n <= 64) {
        for (std::size_t i = 0; i < n; ++i) keys[i] = load(i);
        std::sort(keys.begin(), keys.end());
        for (std::size_t i = 0; i < n; ++i) emit(i, keys[i]);
        return;
    }
    if (2 * shift <= 32) {
        thread_local std::vector<std::uint32_t> narrow;  // reused: no allocation once grown
        narrow.resize(2 * n);
        lsdRadixSortLoaded(
            n, [&load](std::size_t i) { return static_cast<std::uint32_t>(load(i)); },
            narrow.data(), narrow.data() + n, 0, 2 * shift, emit);
        return;
    }
    scratch.resize(n);
    lsdRadixSortLoaded(n, load, keys.data(), scratch.data(), 0, 2 * shift, emit);
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

// The broad phases' pair sort (keysToSortedPairs) against std::sort on every path: few keys (a
// comparison sort), keys of at most 32 bits (radix-sorted as 32-bit integers) and wider ones
// (as 64-bit), with ids either way round in the keys and the smallest and largest ids; and the
// order-preserving map of coordinates to integers the coordinate sorts use.
#include "broadphase/radix_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace collision {
namespace {

struct PairKeys {
    std::vector<std::uint64_t> keys;
    std::vector<ProxyPair> sorted;  // what keysToSortedPairs must write
};

// `count` distinct pairs of ids below 2^shift, among them (0, 2^shift - 1). Keys are (a, b) or,
// with `either_way`, (b, a) for about half of them.
PairKeys randomPairs(std::mt19937& rng, int shift, std::size_t count, bool either_way) {
    const auto ids = static_cast<ProxyId>(1u << shift);
    std::uniform_int_distribution<ProxyId> id(0, ids - 1);
    std::set<std::pair<ProxyId, ProxyId>> set;
    set.insert({0, ids - 1});
    while (set.size() < count) {
        const ProxyId x = id(rng), y = id(rng);
        if (x != y) set.insert({std::min(x, y), std::max(x, y)});
    }
    PairKeys out;
    for (const auto& [a, b] : set) out.sorted.push_back(ProxyPair{a, b});
    std::vector<ProxyPair> shuffled = out.sorted;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    for (const ProxyPair& p : shuffled) {
        const bool swap = either_way && (rng() & 1u);
        const auto first = std::uint64_t(swap ? p.b : p.a),
                   second = std::uint64_t(swap ? p.a : p.b);
        out.keys.push_back(first << shift | second);
    }
    return out;
}

TEST(KeysToSortedPairs, EqualsStdSortOnEveryPath) {
    std::mt19937 rng(19);
    std::vector<std::uint64_t> scratch;
    std::vector<ProxyPair> pairs;
    struct Case {
        int shift;
        std::size_t count;
    };
    // Few keys; 24, 20 and 16 bits (32-bit keys; 1k ids); 34 bits (64-bit keys; 100k ids); 44
    // bits, few keys among many ids.
    for (const Case c : {Case{6, 40}, Case{12, 300}, Case{10, 3000}, Case{8, 5000},
                         Case{17, 300000}, Case{22, 500}}) {
        for (const bool either_way : {false, true}) {
            PairKeys in = randomPairs(rng, c.shift, c.count, either_way);
            radix::keysToSortedPairs(in.keys, scratch, c.shift, pairs, either_way);
            EXPECT_EQ(pairs, in.sorted) << "shift " << c.shift << ", " << c.count << " pairs";
        }
    }
}

// orderedBits is strictly increasing over floats and doubles, negative and positive, tiny and
// huge, infinite, and maps -0 and +0 alike: an LSD radix sort of its values sorts the numbers.
template <typename T>
void expectOrderedBitsIncreasing() {
    constexpr T kInf = std::numeric_limits<T>::infinity();
    std::vector<T> v = {-kInf, -std::numeric_limits<T>::max(), T(-2048), T(-1), T(-0.5),
                        -std::numeric_limits<T>::min(), -std::numeric_limits<T>::denorm_min(), T(0),
                        std::numeric_limits<T>::denorm_min(), std::numeric_limits<T>::min(),
                        T(0.5), T(1), T(2048), std::numeric_limits<T>::max(), kInf};
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1, 1);
    std::uniform_int_distribution<int> exponent(-120, 120);
    for (int i = 0; i < 5000; ++i) v.push_back(T(std::ldexp(unit(rng), exponent(rng))));
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());  // -0 == +0: one of them stays
    for (std::size_t i = 1; i < v.size(); ++i) {
        EXPECT_LT(radix::orderedBits(v[i - 1]), radix::orderedBits(v[i]))
            << v[i - 1] << " " << v[i];
    }
    EXPECT_EQ(radix::orderedBits(T(-0.0)), radix::orderedBits(T(0)));
}

TEST(OrderedBits, IncreasesWithTheValueAndMapsBothZerosAlike) {
    expectOrderedBitsIncreasing<float>();
    expectOrderedBitsIncreasing<double>();
}

}  // namespace
}  // namespace collision

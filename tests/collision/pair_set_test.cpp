// The broad phases' flat pair set against std::set on random insert/erase churn, including
// erasing absent keys, re-inserting present ones, long probe runs and growth.
#include "broadphase/pair_set.h"

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <vector>

namespace collision {
namespace {

std::set<std::uint64_t> contents(const PairSet& s) {
    std::set<std::uint64_t> out;
    s.forEach([&](std::uint64_t k) { EXPECT_TRUE(out.insert(k).second) << "duplicate " << k; });
    return out;
}

TEST(PairSet, EqualsStdSetUnderRandomChurn) {
    std::mt19937_64 rng(7);
    for (const std::uint64_t universe : {8u, 100u, 5000u}) {
        PairSet set;
        std::set<std::uint64_t> reference;
        for (int op = 0; op < 200000; ++op) {
            // Keys shaped like packed pairs, from a small universe so that erases hit.
            const std::uint64_t k = ((rng() % universe) << 32) | (rng() % 7);
            if (rng() % 3 == 0) {
                set.erase(k);
                reference.erase(k);
            } else {
                set.insert(k);
                reference.insert(k);
            }
            ASSERT_EQ(set.size(), reference.size());
            if (op % 20000 == 0) {
                ASSERT_EQ(contents(set), reference);
            }
        }
        EXPECT_EQ(contents(set), reference);
        set.clear();
        EXPECT_EQ(set.size(), 0u);
        EXPECT_TRUE(contents(set).empty());
    }
}

TEST(PairSet, CollidingHomesKeepEveryMemberReachable) {
    // Keys that differ only in high bits share long probe runs; erasing from the middle of a
    // run must shift the rest back so every remaining key is still found.
    PairSet set;
    std::vector<std::uint64_t> keys;
    for (std::uint64_t i = 0; i < 500; ++i) keys.push_back(i << 40);
    for (std::uint64_t k : keys) set.insert(k);
    for (std::size_t i = 0; i < keys.size(); i += 2) set.erase(keys[i]);
    std::set<std::uint64_t> expected;
    for (std::size_t i = 1; i < keys.size(); i += 2) expected.insert(keys[i]);
    EXPECT_EQ(contents(set), expected);
    for (std::size_t i = 1; i < keys.size(); i += 2) {
        set.erase(keys[i]);
    }
    EXPECT_EQ(set.size(), 0u);
}

}  // namespace
}  // namespace collision

// tests/collision/bvh_typed_tests.h -- what the typed BVH tests share: every volume type of
// collision::BvhVolumeTypes as a GoogleTest type list, each test named by the volume's name.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "collision/bvh/bvh.h"

namespace bvh_typed_tests {

template <class T>
struct TupleToTypes;
template <class... Ts>
struct TupleToTypes<std::tuple<Ts...>> {
    using type = ::testing::Types<Ts...>;
};

}  // namespace bvh_typed_tests

/// Every bounding-volume type of the hierarchy, for TYPED_TEST_SUITE.
using BvhVolumeTestTypes = bvh_typed_tests::TupleToTypes<collision::BvhVolumeTypes>::type;

/// Names each typed test after its volume type ("obb", "kdop14", ...).
struct BvhVolumeTestName {
    template <class BV>
    static std::string GetName(int) {
        return std::string(collision::BvName<BV>::value);
    }
};

// tests/collision/contact_box_box_test.cpp -- the pieces of box-box contact that choose by
// selects instead of branches (boxFeature, reduceManifold) against plain references that test
// one condition at a time: the same feature, the same chosen points, on random and degenerate
// input (points on a box's corners, edges and faces, within the tolerance of them, NaN; manifolds
// with tied depths, repeated and collinear points).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "narrowphase/contact_pairs.h"
#include "test_random.h"

namespace {

using collision::Feature;
using collision::FeatureType;
using collision::Real;
using collision::Vec3;
namespace pairs = collision::contact_pairs;

// The axes tested in turn: on how many face planes p lies (within tol), and which.
Feature referenceBoxFeature(const Vec3& half, const Vec3& p, Real tol) {
    int count = 0;
    int free_axis = -1;
    int face_axis = -1;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(p[k]) >= half[k] - tol) {
            ++count;
            face_axis = k;
        } else {
            free_axis = k;
        }
    }
    if (count == 3) {
        return {FeatureType::Vertex,
                (p.x() > 0 ? 1 : 0) + (p.y() > 0 ? 2 : 0) + (p.z() > 0 ? 4 : 0)};
    }
    if (count == 2) {
        const int i = free_axis == 0 ? 1 : 0;
        const int j = free_axis == 2 ? 1 : 2;
        return {FeatureType::Edge, 4 * free_axis + (p[i] > 0 ? 1 : 0) + (p[j] > 0 ? 2 : 0)};
    }
    if (count == 1) return {FeatureType::Face, 2 * face_axis + (p[face_axis] > 0 ? 1 : 0)};
    return {};
}

// Gregorius's four points, each choice made by an if.
int referenceReduce(const std::vector<Vec3>& p, const std::vector<Real>& depth, const Vec3& normal,
                    std::array<int, 4>& chosen) {
    const int n = static_cast<int>(p.size());
    if (n <= 4) {
        for (int i = 0; i < n; ++i) chosen[static_cast<std::size_t>(i)] = i;
        return n;
    }
    const auto at = [&](int i) -> const Vec3& { return p[static_cast<std::size_t>(i)]; };
    int i0 = 0;
    for (int i = 1; i < n; ++i) {
        if (depth[static_cast<std::size_t>(i)] > depth[static_cast<std::size_t>(i0)]) i0 = i;
    }
    int i1 = -1;
    Real best = -1;
    for (int i = 0; i < n; ++i) {
        const Real d = (at(i) - at(i0)).squaredNorm();
        if (i != i0 && d > best) {
            best = d;
            i1 = i;
        }
    }
    int i2 = -1;
    Real best_area = -1;
    Real orientation = 1;
    for (int i = 0; i < n; ++i) {
        if (i == i0 || i == i1) continue;
        const Real area = (at(i1) - at(i0)).cross(at(i) - at(i0)).dot(normal);
        if (std::abs(area) > best_area) {
            best_area = std::abs(area);
            i2 = i;
            orientation = area < 0 ? Real(-1) : Real(1);
        }
    }
    int i3 = -1;
    Real best_out = 0;
    const std::array<int, 3> tri{i0, i1, i2};
    for (int i = 0; i < n; ++i) {
        if (i == i0 || i == i1 || i == i2) continue;
        for (int e = 0; e < 3; ++e) {
            const Vec3& s = at(tri[static_cast<std::size_t>(e)]);
            const Vec3& t = at(tri[static_cast<std::size_t>((e + 1) % 3)]);
            const Real area = -orientation * (t - s).cross(at(i) - s).dot(normal);
            if (area > best_out) {
                best_out = area;
                i3 = i;
            }
        }
    }
    chosen = {i0, i1, i2, i3};
    return i3 < 0 ? 3 : 4;
}

TEST(ContactBoxBox, BoxFeatureEqualsTheAxisByAxisClassification) {
    cdlab_test::Rng rng(11);
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    int checked = 0;
    std::array<int, 4> seen_types{};
    for (int i = 0; i < 200000; ++i) {
        const Real scale = std::pow(Real(10), rng.uniform(-4, 4));
        const Vec3 half = scale * rng.vec(0.05, 1.5);
        const Real tol = scale * (i % 3 == 0 ? Real(0) : Real(1e-9));
        Vec3 p;
        for (int k = 0; k < 3; ++k) {
            // Per coordinate: on a face plane (either side, or just within / beyond the
            // tolerance), inside, zero (either sign), or NaN now and then.
            const Real h = half[k];
            switch (rng.integer(0, 7)) {
                case 0:
                    p[k] = h;
                    break;
                case 1:
                    p[k] = -h;
                    break;
                case 2:
                    p[k] = h - tol;
                    break;
                case 3:
                    p[k] = -(h - tol) - tol * Real(1e-3);
                    break;
                case 4:
                    p[k] = (i % 2 == 0 ? Real(1) : Real(-1)) * Real(0);
                    break;
                case 5:
                    p[k] = i % 97 == 0 ? nan : rng.uniform(-h, h);
                    break;
                default:
                    p[k] = rng.uniform(-1.2 * h, 1.2 * h);
                    break;
            }
        }
        const Feature got = pairs::boxFeature(half, p, tol);
        const Feature want = referenceBoxFeature(half, p, tol);
        ASSERT_EQ(static_cast<int>(got.type), static_cast<int>(want.type))
            << "point " << p.transpose() << " half " << half.transpose() << " tol " << tol;
        ASSERT_EQ(got.index, want.index)
            << "point " << p.transpose() << " half " << half.transpose() << " tol " << tol;
        ++seen_types[static_cast<std::size_t>(want.type)];
        ++checked;
    }
    // Every kind of answer was reached: vertex, edge, face and none.
    for (const int n : seen_types) EXPECT_GT(n, checked / 50);
}

TEST(ContactBoxBox, ReduceManifoldEqualsItsBranchingReference) {
    cdlab_test::Rng rng(12);
    int reduced = 0;
    for (int trial = 0; trial < 100000; ++trial) {
        const int n = 1 + rng.integer(0, 7);
        const Vec3 normal = rng.rotation() * Vec3::UnitZ();
        std::vector<Vec3> p;
        std::vector<Real> depth;
        for (int i = 0; i < n; ++i) {
            const int kind = rng.integer(0, 5);
            if (kind == 0 && i > 0) {
                p.push_back(p[static_cast<std::size_t>(rng.integer(0, i - 1))]);  // repeated point
            } else if (kind == 1 && i > 1) {  // on the line of the first two
                p.push_back(p[0] + rng.uniform(-2, 2) * (p[1] - p[0]));
            } else {
                p.push_back(rng.vec(-1, 1));
            }
            // Tied depths often: the first of equal depths must win.
            depth.push_back(trial % 2 == 0 ? Real(rng.integer(0, 2)) : rng.uniform(0, 1));
        }
        std::array<int, 4> got{-7, -7, -7, -7};
        std::array<int, 4> want{-7, -7, -7, -7};
        const int got_n = pairs::reduceManifold(p.data(), depth.data(), n, normal, got);
        const int want_n = referenceReduce(p, depth, normal, want);
        ASSERT_EQ(got_n, want_n) << "trial " << trial;
        for (int k = 0; k < want_n; ++k) {
            ASSERT_EQ(got[static_cast<std::size_t>(k)], want[static_cast<std::size_t>(k)])
                << "trial " << trial << " point " << k;
        }
        if (n > 4) ++reduced;
    }
    EXPECT_GT(reduced, 30000);
}

// signOrPlus by a mask against the select it replaces, on the values where the two could part:
// zeros of either sign, NaN of either sign, infinities, subnormals, the extremes.
TEST(ContactBoxBox, SignOrPlusEqualsItsSelect) {
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    const Real tiny = std::numeric_limits<Real>::denorm_min();
    const Real big = std::numeric_limits<Real>::max();
    const std::vector<Real> special{0,    -Real(0), nan,  -nan,  inf,  -inf, tiny,
                                    -tiny, big,      -big, Real(1), Real(-1), Real(1e-300)};
    cdlab_test::Rng rng(5);
    std::vector<Real> values = special;
    for (int i = 0; i < 1000; ++i) values.push_back(rng.uniform(-1, 1));
    int negative = 0;
    for (const Real x : values) {
        const Real want = x < 0 ? Real(-1) : Real(1);
        const Real got = pairs::signOrPlus(x);
        EXPECT_EQ(std::memcmp(&got, &want, sizeof(Real)), 0) << x;
        if (want < 0) ++negative;
    }
    EXPECT_GT(negative, 400);
    EXPECT_LT(negative, 600);
}

}  // namespace

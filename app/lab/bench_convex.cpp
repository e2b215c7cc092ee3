// app/lab/bench_convex.cpp -- `cdlab bench convex`: the convex contact query against Bullet's GJK/EPA.
// Each workload is a fixed-seed list of random pairs (sizes 0.2..1.5, random orientations) of
// one kind; both libraries answer every pair; timing is the fastest of `passes` passes over the
// whole list divided by the pair count (no per-call clock overhead). Answers are compared as
// signed distances (negative = penetration depth) relative to the pair's size; the "ext" columns
// repeat every pair translated by 1e6 and scaled by 1e-4 and 1e4 and report the largest change
// of the (rescaled) answer, the accuracy at the extremes. Bullet's headers and libraries stay in
// this file (CDLAB_HAVE_BULLET). Fairness: Bullet gets the same geometry with zero margins (a
// btBoxShape in box rows, a btConvexHullShape of the same points in hull rows), and the pairs of
// the separated/penetrating rows are chosen by a ground truth neither library computes
// (signedDistanceReference: closed forms, or the exact projection-overlap reference for boxes).
#include "bench_convex.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "collision/narrowphase/contact.h"
#include "collision/narrowphase/contact_reference.h"
#include "collision/narrowphase/narrow_phase.h"
#include "collision/test_random.h"
#include "collision/test_shapes.h"
#include "output_files.h"

#ifdef CDLAB_HAVE_BULLET
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCapsuleShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#endif

namespace app {
namespace {

namespace fs = std::filesystem;
using collision::ContactState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

constexpr Real kFarOffset = 1e6;

struct Pair {
    Shape a;
    Shape b;
    Pose pose_a;
    Pose pose_b;
    Real scale = 1;  ///< larger bounding radius
};

enum class Want { Separated, Penetrating, Either };

struct Workload {
    std::string name;
    std::string method;  ///< which cdlab path answers it
    ShapeType type_a;
    ShapeType type_b;
    bool as_hulls = false;  ///< boxes given as 8-point hulls: contact() takes GJK/EPA
    Want want;
};

using Random = cdlab_test::Rng;
using cdlab_test::boundingRadius;

Shape randomShape(ShapeType type, Random& rng) {
    switch (type) {
        case ShapeType::Sphere:
            return Shape::sphere(rng.uniform(0.2, 1.5));
        case ShapeType::Capsule:
            return Shape::capsule(rng.uniform(0.2, 0.8), rng.uniform(0.2, 1.5));
        default:
            return Shape::box(rng.vec(0.2, 1.5));
    }
}

// The box as a hull of its 8 corners (its support is then a scan of 8 points).
Shape asHull(const Shape& box) {
    auto hull = std::make_shared<collision::ConvexPolytope>();
    const Vec3& h = box.half_extents;
    for (int i = 0; i < 8; ++i) {
        hull->vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                                    (i & 4) ? h.z() : -h.z());
    }
    // Faces (outward, counter-clockwise): two triangles per box face.
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        hull->faces.push_back({f[0], f[1], f[2]});
        hull->faces.push_back({f[0], f[2], f[3]});
    }
    return Shape::convexHull(hull);
}

std::vector<Pair> makePairs(const Workload& w, int count, Random& rng) {
    std::vector<Pair> pairs;
    pairs.reserve(static_cast<std::size_t>(count));
    while (static_cast<int>(pairs.size()) < count) {
        Pair p;
        p.a = randomShape(w.type_a, rng);
        p.b = randomShape(w.type_b, rng);
        p.scale = std::max(boundingRadius(p.a), boundingRadius(p.b));
        const Real reach = boundingRadius(p.a) + boundingRadius(p.b);
        p.pose_a = Pose{rng.vec(-1, 1), rng.rotation()};
        const Vec3 dir = rng.rotation() * Vec3::UnitX();
        p.pose_b = Pose{p.pose_a.position + rng.uniform(0.05, 1.2) * reach * dir, rng.rotation()};
        // Positions on a 2^-20 grid: adding kFarOffset is then exact, so the translated pair is
        // the same geometry and any change of the answer is the algorithm's rounding.
        for (Pose* pose : {&p.pose_a, &p.pose_b}) {
            for (int k = 0; k < 3; ++k) {
                pose->position[k] = std::ldexp(std::round(std::ldexp(pose->position[k], 20)), -20);
            }
        }
        // A ground truth neither library computes picks the pairs (closed forms; boxes: the
        // exact projection-overlap reference); pairs within 1e-3 * size of touching, or that
        // the reference cannot place, are left out so the comparison is where the answer is
        // well defined.
        const collision::SignedDistanceBounds truth =
            collision::signedDistanceReference(p.a, p.pose_a, p.b, p.pose_b);
        const bool separated = truth.lower > 1e-3 * p.scale;
        const bool penetrating = truth.upper < -1e-3 * p.scale;
        if (w.want == Want::Separated && !separated) continue;
        if (w.want == Want::Penetrating && !penetrating) continue;
        if (w.want == Want::Either && !separated && !penetrating) continue;
        if (w.as_hulls) {
            p.a = asHull(p.a);
            p.b = asHull(p.b);
        }
        pairs.push_back(std::move(p));
    }
    return pairs;
}

// The same pairs moved far from the origin or scaled: exact geometry changes (the offset is
// added exactly to grid positions; scaling rounds once, ~1e-16 relative), so the answer divided
// by the factor should not move beyond rounding relative to the size.
struct Variant {
    const char* name;
    Real factor;
    Real offset;
};
constexpr std::array<Variant, 3> kVariants{
    {{"far", 1, kFarOffset}, {"small", 1e-4, 0}, {"large", 1e4, 0}}};

using cdlab_test::scaledShape;

std::vector<Pair> transformed(const std::vector<Pair>& pairs, const Variant& v) {
    std::vector<Pair> out;
    out.reserve(pairs.size());
    for (const Pair& p : pairs) {
        Pair q;
        q.a = scaledShape(p.a, v.factor);
        q.b = scaledShape(p.b, v.factor);
        q.pose_a =
            Pose{v.factor * p.pose_a.position + Vec3::Constant(v.offset), p.pose_a.orientation};
        q.pose_b =
            Pose{v.factor * p.pose_b.position + Vec3::Constant(v.offset), p.pose_b.orientation};
        q.scale = p.scale * v.factor;
        out.push_back(std::move(q));
    }
    return out;
}

struct Answers {
    std::vector<Real> signed_distance;
    int failed = 0;
    double us = 0;  ///< fastest pass, microseconds per query
};

// query(i) answers pair i; the fastest of `passes` passes over all pairs is kept.
template <typename Query>
Answers timeQueries(std::size_t n, int passes, Query&& query) {
    Answers ans;
    ans.signed_distance.assign(n, 0);
    double best = std::numeric_limits<double>::infinity();
    for (int pass = 0; pass < std::max(passes, 1); ++pass) {
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t i = 0; i < n; ++i) ans.signed_distance[i] = query(i);
        const auto stop = std::chrono::steady_clock::now();
        best = std::min(best, std::chrono::duration<double, std::micro>(stop - start).count());
    }
    ans.us = n > 0 ? best / static_cast<double>(n) : 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(ans.signed_distance[i])) ++ans.failed;
    }
    return ans;
}

#ifdef CDLAB_HAVE_BULLET
// Used only beside Bullet: the pairs Bullet and cdlab disagree on are retried on cdlab's other path.
bool isBoxLike(const Shape& s) {
    return s.type == ShapeType::Box || s.type == ShapeType::ConvexHull;
}

// The same geometry through cdlab's other code path: a box as its 8-point hull (GJK/EPA) and a
// box-hull back as a box (SAT, closed forms); round shapes stay.
Shape otherPath(const Shape& s) {
    if (s.type == ShapeType::Box) return asHull(s);
    if (s.type == ShapeType::ConvexHull) return Shape::box(s.hull->vertices.back().cwiseAbs());
    return s;
}
#endif

Real cdlabQuery(const Pair& p) {
    const collision::ContactOutput out = contact(p.a, p.pose_a, p.b, p.pose_b);
    if (out.state == ContactState::Failed) return std::numeric_limits<Real>::quiet_NaN();
    return out.signed_distance;
}

#ifdef CDLAB_HAVE_BULLET
std::unique_ptr<btConvexShape> bulletShape(const Shape& s) {
    switch (s.type) {
        // Spheres and capsules keep Bullet's implicit margin: it is their radius (a point or a
        // segment inflated by it, as cdlab's cores), so the geometry is exact.
        case ShapeType::Sphere:
            return std::make_unique<btSphereShape>(s.radius);
        case ShapeType::Capsule:
            return std::make_unique<btCapsuleShape>(s.radius, 2 * s.half_height);  // along y
        case ShapeType::Box: {
            auto box = std::make_unique<btBoxShape>(
                btVector3(s.half_extents.x(), s.half_extents.y(), s.half_extents.z()));
            box->setMargin(0);  // the exact box: no rounded margin shell
            return box;
        }
        default: {
            // Hulls: the same points (a box's 8 corners in the hull rows), no margin, so Bullet
            // runs the same point-cloud support as cdlab's GJK/EPA path.
            auto hull = std::make_unique<btConvexHullShape>();
            for (const Vec3& v : s.hull->vertices)
                hull->addPoint(btVector3(v.x(), v.y(), v.z()), false);
            hull->recalcLocalAabb();
            hull->setMargin(0);
            return hull;
        }
    }
}

btTransform bulletTransform(const Pose& p) {
    const Quat& q = p.orientation;
    return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()),
                       btVector3(p.position.x(), p.position.y(), p.position.z()));
}

struct BulletPair {
    std::unique_ptr<btConvexShape> a;
    std::unique_ptr<btConvexShape> b;
};

std::vector<BulletPair> bulletShapes(const std::vector<Pair>& pairs) {
    std::vector<BulletPair> shapes(pairs.size());
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        shapes[i].a = bulletShape(pairs[i].a);
        shapes[i].b = bulletShape(pairs[i].b);
    }
    return shapes;
}

// btGjkPairDetector with Bullet's EPA (btGjkEpaPenetrationDepthSolver); m_distance is negative
// when penetrating. No result counts as a failure.
Real bulletQuery(const BulletPair& shapes, const Pair& p) {
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver depth_solver;
    btGjkPairDetector detector(shapes.a.get(), shapes.b.get(), &simplex, &depth_solver);
    btGjkPairDetector::ClosestPointInput in;
    in.m_transformA = bulletTransform(p.pose_a);
    in.m_transformB = bulletTransform(p.pose_b);
    btPointCollector result;
    detector.getClosestPoints(in, result, nullptr);
    if (!result.m_hasResult) return std::numeric_limits<Real>::quiet_NaN();
    return result.m_distance;
}
#endif

struct Row {
    std::string workload;
    std::string method;
    int queries = 0;
    int colliding = 0;
    double cdlab_us = 0;
    double bullet_us = -1;  ///< -1 when Bullet is not built in
    int disagreements = 0;
    /// Disagreements where cdlab's other path (boxes as hulls through GJK/EPA, or hulls as boxes
    /// through SAT / closed forms) gives cdlab's answer too; -1 when the pair has no box.
    int disagreements_confirmed = -1;
    nlohmann::json disagreement_examples = nlohmann::json::array();
    double max_difference = 0;  ///< max |ours - Bullet's| / size
    /// Per variant (far, small, large): max |answer / factor - answer| / size; NaN answers are
    /// counted in *_variant_failed instead.
    std::array<double, 3> cdlab_variant_error{0, 0, 0};
    std::array<double, 3> bullet_variant_error{-1, -1, -1};
    int cdlab_variant_failed = 0;
    int bullet_variant_failed = 0;
    int cdlab_failed = 0;
    int bullet_failed = 0;
};

// Largest relative change of the answers under variant k; NaNs counted in `failed`.
void variantError(const std::vector<Pair>& pairs, const std::vector<Real>& base,
                  const std::vector<Real>& moved, Real factor, double& error, int& failed) {
    error = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        const double e = std::abs(moved[i] / factor - base[i]) / pairs[i].scale;
        if (std::isfinite(e)) {
            error = std::max(error, e);
        } else if (std::isfinite(base[i])) {
            ++failed;
        }
    }
}

Row runWorkload(const Workload& w, int index, const BenchConvexOptions& options) {
    Random rng(options.seed * 1000 + static_cast<std::uint64_t>(index));
    const std::vector<Pair> pairs = makePairs(w, options.queries, rng);
    std::vector<std::vector<Pair>> variants;
    for (const Variant& v : kVariants) variants.push_back(transformed(pairs, v));
    Row row;
    row.workload = w.name;
    row.method = w.method;
    row.queries = static_cast<int>(pairs.size());
    const Answers ours = timeQueries(pairs.size(), options.passes,
                                     [&](std::size_t i) { return cdlabQuery(pairs[i]); });
    row.cdlab_us = ours.us;
    row.cdlab_failed = ours.failed;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        if (ours.signed_distance[i] <= 0) ++row.colliding;
    }
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        std::vector<Real> moved(pairs.size());
        for (std::size_t i = 0; i < pairs.size(); ++i) moved[i] = cdlabQuery(variants[k][i]);
        variantError(pairs, ours.signed_distance, moved, kVariants[k].factor,
                     row.cdlab_variant_error[k], row.cdlab_variant_failed);
    }
#ifdef CDLAB_HAVE_BULLET
    const std::vector<BulletPair> shapes = bulletShapes(pairs);
    const Answers theirs = timeQueries(pairs.size(), options.passes, [&](std::size_t i) {
        return bulletQuery(shapes[i], pairs[i]);
    });
    row.bullet_us = theirs.us;
    row.bullet_failed = theirs.failed;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        const double diff = std::abs(ours.signed_distance[i] - theirs.signed_distance[i]);
        const double rel = diff / pairs[i].scale;
        if (!(rel <= options.tolerance)) {  // NaN (a failure) disagrees too
            ++row.disagreements;
            const bool has_box = isBoxLike(pairs[i].a) || isBoxLike(pairs[i].b);
            Real other = std::numeric_limits<Real>::quiet_NaN();
            if (has_box) {
                Pair alt = pairs[i];
                alt.a = otherPath(pairs[i].a);
                alt.b = otherPath(pairs[i].b);
                other = cdlabQuery(alt);
                if (row.disagreements_confirmed < 0) row.disagreements_confirmed = 0;
                if (std::abs(other - ours.signed_distance[i]) <=
                    options.tolerance * pairs[i].scale) {
                    ++row.disagreements_confirmed;
                }
            }
            if (row.disagreement_examples.size() < 3) {
                row.disagreement_examples.push_back(
                    {{"pair", i},
                     {"size", pairs[i].scale},
                     {"cdlab", ours.signed_distance[i]},
                     {"cdlab_other_path",
                      has_box ? nlohmann::json(other) : nlohmann::json(nullptr)},
                     {"bullet", theirs.signed_distance[i]}});
            }
        }
        if (std::isfinite(rel)) row.max_difference = std::max(row.max_difference, rel);
    }
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        const std::vector<BulletPair> moved_shapes = bulletShapes(variants[k]);
        std::vector<Real> moved(pairs.size());
        for (std::size_t i = 0; i < pairs.size(); ++i) {
            moved[i] = bulletQuery(moved_shapes[i], variants[k][i]);
        }
        variantError(pairs, theirs.signed_distance, moved, kVariants[k].factor,
                     row.bullet_variant_error[k], row.bullet_variant_failed);
    }
#endif
    return row;
}

double maxOf(const std::array<double, 3>& v) { return std::max({v[0], v[1], v[2]}); }

nlohmann::json rowJson(const Row& r) {
    nlohmann::json j{{"workload", r.workload},
                     {"method", r.method},
                     {"queries", r.queries},
                     {"colliding", r.colliding},
                     {"cdlab_us", r.cdlab_us},
                     {"cdlab_failed", r.cdlab_failed},
                     {"cdlab_variant_failed", r.cdlab_variant_failed}};
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        j[std::string("cdlab_") + kVariants[k].name + "_error"] = r.cdlab_variant_error[k];
    }
    if (r.bullet_us >= 0) {
        j["bullet_us"] = r.bullet_us;
        j["bullet_failed"] = r.bullet_failed;
        j["bullet_variant_failed"] = r.bullet_variant_failed;
        for (std::size_t k = 0; k < kVariants.size(); ++k) {
            j[std::string("bullet_") + kVariants[k].name + "_error"] = r.bullet_variant_error[k];
        }
        j["disagreements"] = r.disagreements;
        j["disagreements_confirmed"] = r.disagreements_confirmed;
        j["disagreement_examples"] = r.disagreement_examples;
        j["max_difference"] = r.max_difference;
    } else {
        j["bullet_us"] = nullptr;
    }
    return j;
}

void printTable(const std::vector<Row>& rows, double tolerance, std::ostream& out) {
    out << std::left << std::setw(29) << "workload" << std::setw(12) << "cdlab_path" << std::right
        << std::setw(8) << "queries" << std::setw(7) << "hits" << std::setw(10) << "cdlab_us"
        << std::setw(10) << "bullet_us" << std::setw(7) << "ratio" << std::setw(9) << "disagree"
        << std::setw(10) << "confirmed" << std::setw(10) << "max_diff" << std::setw(11)
        << "cdlab_ext" << std::setw(11) << "bullet_ext" << std::setw(8) << "failed"
        << "\n";
    for (const Row& r : rows) {
        out << std::left << std::setw(29) << r.workload << std::setw(12) << r.method << std::right
            << std::setw(8) << r.queries << std::setw(7) << r.colliding << std::fixed
            << std::setprecision(3) << std::setw(10) << r.cdlab_us;
        if (r.bullet_us >= 0) {
            out << std::setw(10) << r.bullet_us << std::setw(7) << std::setprecision(2)
                << r.cdlab_us / r.bullet_us << std::setw(9) << r.disagreements << std::setw(10)
                << (r.disagreements_confirmed < 0 ? std::string("-")
                                                  : std::to_string(r.disagreements_confirmed))
                << std::scientific << std::setprecision(1) << std::setw(10) << r.max_difference
                << std::setw(11) << maxOf(r.cdlab_variant_error) << std::setw(11)
                << maxOf(r.bullet_variant_error);
        } else {
            out << std::setw(10) << "n/a" << std::setw(7) << "n/a" << std::setw(9) << "n/a"
                << std::setw(10) << "n/a" << std::setw(10) << "n/a" << std::scientific
                << std::setprecision(1) << std::setw(11) << maxOf(r.cdlab_variant_error)
                << std::setw(11) << "n/a";
        }
        out << std::defaultfloat << std::setw(8) << r.cdlab_failed + r.cdlab_variant_failed << "\n";
    }
    out << "ratio = cdlab_us / bullet_us; disagree: |signed distance difference| > " << tolerance
        << " * size; confirmed: of those, how many cdlab's other path (box <-> 8-point hull) "
           "answers like cdlab; ext: largest change of answer / factor after translating by 1e6 or "
           "scaling"
           " by 1e-4 and 1e4, relative to size (JSON: per variant); failed: cdlab Failed states\n";
}

}  // namespace

int runBenchConvex(const BenchConvexOptions& options, std::ostream& out, std::ostream& err) {
    if (options.queries < 1 || options.passes < 1 || !(options.tolerance > 0)) {
        err << "cdlab bench convex: --queries and --passes must be >= 1 and --tolerance > 0\n";
        return 2;
    }
    const std::vector<Workload> workloads{
        {"box-box separated", "SAT+GJK", ShapeType::Box, ShapeType::Box, false, Want::Separated},
        {"hullbox-hullbox separated", "GJK", ShapeType::Box, ShapeType::Box, true, Want::Separated},
        {"box-box penetrating", "SAT+clip", ShapeType::Box, ShapeType::Box, false,
         Want::Penetrating},
        {"hullbox-hullbox penetrating", "GJK+EPA", ShapeType::Box, ShapeType::Box, true,
         Want::Penetrating},
        {"sphere-sphere", "closed form", ShapeType::Sphere, ShapeType::Sphere, false, Want::Either},
        {"sphere-capsule", "closed form", ShapeType::Sphere, ShapeType::Capsule, false,
         Want::Either},
        {"capsule-capsule", "closed form", ShapeType::Capsule, ShapeType::Capsule, false,
         Want::Either},
        {"sphere-box", "closed form", ShapeType::Sphere, ShapeType::Box, false, Want::Either},
    };
    std::vector<Row> rows;
    for (std::size_t k = 0; k < workloads.size(); ++k) {
        rows.push_back(runWorkload(workloads[k], static_cast<int>(k), options));
    }
    printTable(rows, options.tolerance, out);

    if (options.json) {
        nlohmann::json doc;
        doc["benchmark"] = "convex";
        doc["tolerance"] = options.tolerance;
        doc["queries"] = options.queries;
        doc["passes"] = options.passes;
        doc["seed"] = options.seed;
        doc["far_offset"] = kFarOffset;
#ifdef CDLAB_HAVE_BULLET
        doc["bullet"] = true;
#else
        doc["bullet"] = false;
#endif
        doc["rows"] = nlohmann::json::array();
        for (const Row& r : rows) doc["rows"].push_back(rowJson(r));
        if (!writeTextReporting(*options.json, doc.dump(2) + "\n", err)) return 1;
    }
    return 0;
}

}  // namespace app

// app/lab/bench/bench_convex.cpp -- `cdlab bench convex`: cdlab's convex contact query beside Bullet,
// each pair family against the path Bullet itself runs for it (its dispatcher's algorithm:
// btBoxBoxDetector for boxes, the sphere-sphere and sphere-box algorithms, the capsule cases of
// btConvexConvexAlgorithm) and against Bullet's general GJK/EPA (bench_convex_peers.h). Each
// workload is a fixed-seed list of random pairs (sizes 0.2..1.5, random orientations) of one
// kind, chosen by the long-double ground truth (convex_reference.h) to be separated or
// penetrating by more than 1e-3 of their size; rows of the same name share their pairs. Timing:
// thread CPU time of whole passes over the list divided by the pair count, the median of
// `passes` passes (no per-call clock overhead), cdlab's and Bullet's passes interleaved.
// Accuracy: every answer's signed distance, normal and witness points are checked against the
// ground truth, relative to the pair's size; the "ext" columns repeat every pair translated by
// 1e6 and scaled by 1e-4 and 1e4 and report the largest change of the (rescaled) answer.
#include "bench_convex.h"

#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_convex_peers.h"
#include "collision/narrowphase/contact.h"
#include "collision/test_random.h"
#include "collision/test_shapes.h"
#include "convex_reference.h"
#include "output_files.h"

namespace app {
namespace {

using collision::ContactState;
using collision::Pose;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

constexpr Real kFarOffset = 1e6;

enum class Want { Separated, Penetrating, Either };

struct Workload {
    std::string name;
    std::string method;  ///< which cdlab path answers it
    ShapeType type_a;
    ShapeType type_b;
    bool as_hulls = false;  ///< boxes given as 8-point hulls: contact() takes GJK/EPA
    Want want;
    BulletPath peer;
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

std::vector<ConvexPair> makePairs(const Workload& w, int count, Random& rng,
                                  std::vector<Real>& truth) {
    std::vector<ConvexPair> pairs;
    pairs.reserve(static_cast<std::size_t>(count));
    truth.clear();
    while (static_cast<int>(pairs.size()) < count) {
        ConvexPair p;
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
        // Pairs within 1e-3 * size of touching are left out, so the comparison is where the
        // answer is well defined.
        const Real d = exactSignedDistance(p.a, p.pose_a, p.b, p.pose_b);
        const bool separated = d > 1e-3 * p.scale;
        const bool penetrating = d < -1e-3 * p.scale;
        if (w.want == Want::Separated && !separated) continue;
        if (w.want == Want::Penetrating && !penetrating) continue;
        if (w.want == Want::Either && !separated && !penetrating) continue;
        if (w.as_hulls) {
            p.a = asHull(p.a);
            p.b = asHull(p.b);
        }
        pairs.push_back(std::move(p));
        truth.push_back(d);
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

std::vector<ConvexPair> transformed(const std::vector<ConvexPair>& pairs, const Variant& v) {
    std::vector<ConvexPair> out;
    out.reserve(pairs.size());
    for (const ConvexPair& p : pairs) {
        ConvexPair q;
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

double threadCpuMicroseconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
}

struct Answers {
    std::vector<ContactAnswer> answers;
    int failed = 0;
    double us = 0;  ///< median pass, thread CPU microseconds per query
};

// Times one pass over all pairs, query(i) answering pair i, into `out`.
template <typename Query>
double timePass(std::size_t n, Answers& out, Query&& query) {
    const double start = threadCpuMicroseconds();
    for (std::size_t i = 0; i < n; ++i) out.answers[i] = query(i);
    return threadCpuMicroseconds() - start;
}

// The median pass per query, and the answers counted as failed.
void finish(std::size_t n, std::vector<double>& times, Answers& out) {
    std::sort(times.begin(), times.end());
    const double median = times[times.size() / 2];
    out.us = n > 0 ? median / static_cast<double>(n) : 0;
    for (const ContactAnswer& a : out.answers) {
        if (!std::isfinite(a.signed_distance)) ++out.failed;
    }
}

// `passes` passes over all pairs of each query, interleaved (ours then theirs, then theirs then
// ours, and so on), so that a stretch where the machine runs slow costs both the same; each
// keeps its median pass. Without `theirs`, ours alone.
template <typename Ours, typename Theirs>
void timeQueries(std::size_t n, int passes, Ours&& ours, Answers& ours_out, Theirs* theirs,
                 Answers* theirs_out) {
    ours_out.answers.assign(n, ContactAnswer{});
    if (theirs != nullptr) theirs_out->answers.assign(n, ContactAnswer{});
    std::vector<double> ours_times;
    std::vector<double> theirs_times;
    for (int pass = 0; pass < std::max(passes, 1); ++pass) {
        const bool ours_first = pass % 2 == 0;
        if (ours_first) ours_times.push_back(timePass(n, ours_out, ours));
        if (theirs != nullptr) theirs_times.push_back(timePass(n, *theirs_out, *theirs));
        if (!ours_first) ours_times.push_back(timePass(n, ours_out, ours));
    }
    finish(n, ours_times, ours_out);
    if (theirs != nullptr) finish(n, theirs_times, *theirs_out);
}

ContactAnswer cdlabQuery(const ConvexPair& p) {
    const collision::ContactOutput out = contact(p.a, p.pose_a, p.b, p.pose_b);
    if (out.state == ContactState::Failed) return ContactAnswer{};
    return {out.signed_distance, out.normal, out.point_a, out.point_b};
}

/// Errors of one library's answers against the ground truth, relative to each pair's size.
struct Accuracy {
    double depth = 0;    ///< max |signed distance - exact|
    int wrong = 0;       ///< answers whose signed distance is off by more than the tolerance
    double normal = 0;   ///< max overlap(normal) + exact: 0 iff the normal is a valid one
    double witness = 0;  ///< max distance of a witness point from its shape's surface
};

Accuracy accuracy(const std::vector<ConvexPair>& pairs, const std::vector<Real>& truth,
                  const std::vector<ContactAnswer>& answers, double tolerance) {
    Accuracy acc;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        const ConvexPair& p = pairs[i];
        const ContactAnswer& a = answers[i];
        if (!std::isfinite(a.signed_distance)) continue;  // counted as failed
        const double depth = std::abs(a.signed_distance - truth[i]) / p.scale;
        acc.depth = std::max(acc.depth, depth);
        if (!(depth <= tolerance)) ++acc.wrong;
        const Real len = a.normal.norm();
        const double normal =
            len > 0 ? (exactOverlapAlong(p.a, p.pose_a, p.b, p.pose_b, a.normal / len) + truth[i]) /
                          p.scale
                    : std::numeric_limits<double>::infinity();
        acc.normal = std::max(acc.normal, normal);
        const double witness_a = std::abs(surfaceDistance(p.a, p.pose_a, a.point_a)) / p.scale;
        const double witness_b = std::abs(surfaceDistance(p.b, p.pose_b, a.point_b)) / p.scale;
        acc.witness = std::max({acc.witness, witness_a, witness_b});
    }
    return acc;
}

struct Row {
    std::string workload;
    std::string method;
    std::string peer = "n/a";
    int queries = 0;
    int colliding = 0;
    double cdlab_us = 0;
    double bullet_us = -1;  ///< -1 when Bullet is not built in
    Accuracy cdlab;
    Accuracy bullet;
    /// Per variant (far, small, large): max |answer / factor - answer| / size; NaN answers are
    /// counted in *_variant_failed instead.
    std::array<double, 3> cdlab_variant_error{0, 0, 0};
    std::array<double, 3> bullet_variant_error{-1, -1, -1};
    int cdlab_variant_failed = 0;
    int bullet_variant_failed = 0;
    int cdlab_failed = 0;
    int bullet_failed = 0;
};

// Largest relative change of the answers under a variant; NaNs counted in `failed`.
void variantError(const std::vector<ConvexPair>& pairs, const std::vector<ContactAnswer>& base,
                  const std::vector<ContactAnswer>& moved, Real factor, double& error,
                  int& failed) {
    error = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        const double e =
            std::abs(moved[i].signed_distance / factor - base[i].signed_distance) / pairs[i].scale;
        if (std::isfinite(e)) {
            error = std::max(error, e);
        } else if (std::isfinite(base[i].signed_distance)) {
            ++failed;
        }
    }
}

struct PairSet {
    std::vector<ConvexPair> pairs;
    std::vector<Real> truth;
    std::vector<std::vector<ConvexPair>> variants;
};

PairSet makePairSet(const Workload& w, std::uint64_t seed, int queries) {
    PairSet set;
    Random rng(seed);
    set.pairs = makePairs(w, queries, rng, set.truth);
    for (const Variant& v : kVariants) set.variants.push_back(transformed(set.pairs, v));
    return set;
}

Row runWorkload(const Workload& w, const PairSet& set, const BenchConvexOptions& options) {
    const std::vector<ConvexPair>& pairs = set.pairs;
    Row row;
    row.workload = w.name;
    row.method = w.method;
    row.queries = static_cast<int>(pairs.size());
    // Bullet's objects are made before any pass, so its passes can be interleaved with ours.
    std::unique_ptr<BulletConvexPeer> peer;
    if (bulletAvailable()) peer = std::make_unique<BulletConvexPeer>(w.peer, pairs);
    const auto our_query = [&](std::size_t i) { return cdlabQuery(pairs[i]); };
    const auto peer_query = [&](std::size_t i) { return peer->query(i); };
    Answers ours;
    Answers theirs;
    timeQueries(pairs.size(), options.passes, our_query, ours, peer ? &peer_query : nullptr,
                &theirs);
    row.cdlab_us = ours.us;
    row.cdlab_failed = ours.failed;
    row.cdlab = accuracy(pairs, set.truth, ours.answers, options.tolerance);
    for (const ContactAnswer& a : ours.answers) {
        if (a.signed_distance <= 0) ++row.colliding;
    }
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        std::vector<ContactAnswer> moved(pairs.size());
        for (std::size_t i = 0; i < pairs.size(); ++i) moved[i] = cdlabQuery(set.variants[k][i]);
        variantError(pairs, ours.answers, moved, kVariants[k].factor, row.cdlab_variant_error[k],
                     row.cdlab_variant_failed);
    }
    if (!peer) return row;
    row.peer = peer->pathName();
    row.bullet_us = theirs.us;
    row.bullet_failed = theirs.failed;
    row.bullet = accuracy(pairs, set.truth, theirs.answers, options.tolerance);
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        const BulletConvexPeer moved_peer(w.peer, set.variants[k]);
        std::vector<ContactAnswer> moved(pairs.size());
        for (std::size_t i = 0; i < pairs.size(); ++i) moved[i] = moved_peer.query(i);
        variantError(pairs, theirs.answers, moved, kVariants[k].factor,
                     row.bullet_variant_error[k], row.bullet_variant_failed);
    }
    return row;
}

double maxOf(const std::array<double, 3>& v) { return std::max({v[0], v[1], v[2]}); }

nlohmann::json accuracyJson(const Accuracy& a) {
    return {{"depth_error", a.depth},
            {"wrong", a.wrong},
            {"normal_error", a.normal},
            {"witness_error", a.witness}};
}

nlohmann::json rowJson(const Row& r) {
    nlohmann::json j{{"workload", r.workload},
                     {"method", r.method},
                     {"queries", r.queries},
                     {"colliding", r.colliding},
                     {"cdlab_us", r.cdlab_us},
                     {"cdlab_failed", r.cdlab_failed},
                     {"cdlab_variant_failed", r.cdlab_variant_failed},
                     {"cdlab_accuracy", accuracyJson(r.cdlab)}};
    for (std::size_t k = 0; k < kVariants.size(); ++k) {
        j[std::string("cdlab_") + kVariants[k].name + "_error"] = r.cdlab_variant_error[k];
    }
    if (r.bullet_us >= 0) {
        j["bullet_path"] = r.peer;
        j["bullet_us"] = r.bullet_us;
        j["bullet_failed"] = r.bullet_failed;
        j["bullet_variant_failed"] = r.bullet_variant_failed;
        j["bullet_accuracy"] = accuracyJson(r.bullet);
        for (std::size_t k = 0; k < kVariants.size(); ++k) {
            j[std::string("bullet_") + kVariants[k].name + "_error"] = r.bullet_variant_error[k];
        }
    } else {
        j["bullet_us"] = nullptr;
    }
    return j;
}

void printTable(const std::vector<Row>& rows, double tolerance, std::ostream& out) {
    out << std::left << std::setw(28) << "workload" << std::setw(12) << "cdlab_path"
        << std::setw(25) << "bullet_path" << std::right << std::setw(7) << "hits" << std::setw(9)
        << "cdlab_us" << std::setw(10) << "bullet_us" << std::setw(7) << "ratio" << std::setw(10)
        << "cdlab_err" << std::setw(11) << "bullet_err" << std::setw(7) << "wrong"
        << std::setw(11) << "bullet_nrm" << std::setw(10) << "cdlab_ext" << std::setw(11)
        << "bullet_ext" << std::setw(7) << "failed"
        << "\n";
    for (const Row& r : rows) {
        out << std::left << std::setw(28) << r.workload << std::setw(12) << r.method
            << std::setw(25) << r.peer << std::right << std::setw(7) << r.colliding << std::fixed
            << std::setprecision(3) << std::setw(9) << r.cdlab_us;
        if (r.bullet_us >= 0) {
            out << std::setw(10) << r.bullet_us << std::setw(7) << std::setprecision(2)
                << r.cdlab_us / r.bullet_us << std::scientific << std::setprecision(1)
                << std::setw(10) << r.cdlab.depth << std::setw(11) << r.bullet.depth
                << std::setw(7) << r.bullet.wrong << std::setw(11) << r.bullet.normal
                << std::setw(10) << maxOf(r.cdlab_variant_error) << std::setw(11)
                << maxOf(r.bullet_variant_error);
        } else {
            out << std::setw(10) << "n/a" << std::setw(7) << "n/a" << std::scientific
                << std::setprecision(1) << std::setw(10) << r.cdlab.depth << std::setw(11)
                << "n/a" << std::setw(7) << "n/a" << std::setw(11) << "n/a" << std::setw(10)
                << maxOf(r.cdlab_variant_error) << std::setw(11) << "n/a";
        }
        out << std::defaultfloat << std::setw(7) << r.cdlab_failed + r.cdlab_variant_failed << "\n";
    }
    out << "us: thread CPU time per query, median pass (cdlab and Bullet passes interleaved); "
           "ratio = cdlab_us / bullet_us; *_err: largest |signed distance - exact| / size (exact: "
           "long-double closed forms, boxes' 15-axis SAT depth or brute-force distance); wrong: "
           "Bullet answers off by more than "
        << tolerance
        << " * size; bullet_nrm: largest (overlap along Bullet's normal - exact depth) / size, 0 "
           "for a valid normal; ext: largest change of answer / factor after translating by 1e6 "
           "or scaling by 1e-4 and 1e4, relative to size; failed: cdlab Failed states (JSON: "
           "cdlab's normal and witness errors, per variant)\n";
}

std::vector<Workload> workloads() {
    using enum ShapeType;
    const BulletPath general = BulletPath::GeneralGjkEpa;
    const BulletPath own = BulletPath::Dispatcher;
    // Bullet's dispatcher answers contacts, not distances (btBoxBoxDetector reports nothing for
    // boxes apart, the round algorithms nothing beyond the breaking threshold): its rows are
    // penetrating pairs; its general GJK/EPA answers the separated and mixed rows.
    return {
        {"box-box separated", "SAT+GJK", Box, Box, false, Want::Separated, general},
        {"hullbox-hullbox separated", "GJK", Box, Box, true, Want::Separated, general},
        {"box-box penetrating", "SAT+clip", Box, Box, false, Want::Penetrating, own},
        {"box-box penetrating", "SAT+clip", Box, Box, false, Want::Penetrating, general},
        {"hullbox-hullbox penetrating", "GJK+EPA", Box, Box, true, Want::Penetrating, general},
        {"sphere-sphere penetrating", "closed form", Sphere, Sphere, false, Want::Penetrating,
         own},
        {"sphere-sphere", "closed form", Sphere, Sphere, false, Want::Either, general},
        {"sphere-capsule penetrating", "closed form", Sphere, Capsule, false, Want::Penetrating,
         own},
        {"sphere-capsule", "closed form", Sphere, Capsule, false, Want::Either, general},
        {"capsule-capsule penetrating", "closed form", Capsule, Capsule, false,
         Want::Penetrating, own},
        {"capsule-capsule", "closed form", Capsule, Capsule, false, Want::Either, general},
        {"sphere-box penetrating", "closed form", Sphere, Box, false, Want::Penetrating, own},
        {"sphere-box penetrating", "closed form", Sphere, Box, false, Want::Penetrating,
         BulletPath::SphereBoxAlgorithm},
        {"sphere-box", "closed form", Sphere, Box, false, Want::Either, general},
    };
}

}  // namespace

int runBenchConvex(const BenchConvexOptions& options, std::ostream& out, std::ostream& err) {
    if (options.queries < 1 || options.passes < 1 || !(options.tolerance > 0)) {
        err << "cdlab bench convex: --queries and --passes must be >= 1 and --tolerance > 0\n";
        return 2;
    }
    const std::vector<Workload> list = workloads();
    const auto selected = [&](const Workload& w) {
        return w.name.find(options.workload) != std::string::npos;
    };
    if (std::none_of(list.begin(), list.end(), selected)) {
        std::string message = "cdlab bench convex: --workload '";
        message += options.workload;
        message += "' matches no workload\n";
        err << message;
        return 2;
    }
    std::vector<Row> rows;
    PairSet set;
    for (std::size_t k = 0; k < list.size(); ++k) {
        if (!selected(list[k])) continue;
        // Rows of the same name answer the same pairs (the seed of the name's first row).
        std::size_t first = k;
        while (first > 0 && list[first - 1].name == list[k].name) --first;
        if (rows.empty() || rows.back().workload != list[k].name) {
            set = makePairSet(list[first], options.seed * 1000 + first, options.queries);
        }
        rows.push_back(runWorkload(list[k], set, options));
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
        doc["bullet"] = bulletAvailable();
        doc["rows"] = nlohmann::json::array();
        for (const Row& r : rows) doc["rows"].push_back(rowJson(r));
        if (!writeTextReporting(*options.json, doc.dump(2) + "\n", err)) return 1;
    }
    return 0;
}

}  // namespace app

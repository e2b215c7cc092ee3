// app/lab/bench/bench_narrowphase.cpp -- `cdlab bench narrowphase`. Wiring and timing only: trees and
// queries are collision/bvh.h; FCL (when CMake found it, CDLAB_HAVE_FCL) stays in this file. Same
// inputs for every method: one torus mesh for A and B, B placed by the pose (A at the identity).
// The reference answer per pose is cdlab's brute-force triangle loop (intersectMeshMeshBruteForce;
// for --large its sweep form, the same list); cdlab methods must return its pair list exactly,
// FCL's boolean and pair count are compared and mismatches reported (FCL's triangle test is not
// exact).
#include "bench_narrowphase.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <ostream>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "bench_broadphase_measure.h"
#include "bvh_unit_costs.h"
#include "collision/bvh/bvh.h"
#include "collision/test_meshes.h"
#include "output_files.h"

#ifdef CDLAB_HAVE_FCL
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/bvh/detail/BV_splitter.h>
#include <fcl/math/bv/AABB.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/RSS.h>
#include <fcl/math/bv/kDOP.h>
#include <fcl/math/bv/kIOS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>
#endif

namespace app {

namespace {

using collision::Pose;
using collision::Real;
using collision::TriangleMesh;
using collision::Vec3;

// Thread CPU time (threadCpuSeconds): what another process on a shared machine takes does not
// count.
double secondsSince(double t) { return threadCpuSeconds() - t; }

// A torus around local z, ring radius 1, tube radius 0.4: nu segments around the ring, nv around
// the tube, 2 nu nv triangles.
TriangleMesh makeTorus(int nu, int nv) { return cdlab_test::makeTorusMesh(1.0, 0.4, nu, nv); }

// One way of answering the two queries.
class NarrowMethod {
public:
    virtual ~NarrowMethod() = default;
    virtual std::string name() const = 0;
    virtual bool hasCounters() const = 0;
    /// Builds the trees of A and B (the same mesh); the caller times it.
    virtual void build(const TriangleMesh& mesh) = 0;
    virtual bool first(const Pose& b_in_a, collision::BvhQueryStats* stats) = 0;
    /// Number of intersecting triangle pairs; `pairs` (may be null) gets them when available.
    virtual std::size_t all(const Pose& b_in_a, collision::BvhQueryStats* stats,
                            std::vector<collision::TrianglePair>* pairs) = 0;
    /// cdlab only: the trees A and B of the last build (nullptr for other libraries).
    virtual collision::MeshBvh* treeA() { return nullptr; }
    virtual const collision::MeshBvh* treeB() const { return nullptr; }
};

class CdlabMethod final : public NarrowMethod {
public:
    CdlabMethod(std::string_view bv, collision::BvhBuild how) : bv_(bv), how_(how) {}
    std::string name() const override {
        return std::string(bv_) + (how_ == collision::BvhBuild::BottomUp ? "-bu" : "");
    }
    bool hasCounters() const override { return true; }
    void build(const TriangleMesh& mesh) override {
        collision::BvhBuildOptions options;
        options.build = how_;
        a_ = collision::buildMeshBvh(bv_, mesh, options);
        b_ = collision::buildMeshBvh(bv_, mesh, options);
    }
    bool first(const Pose& b_in_a, collision::BvhQueryStats* stats) override {
        return a_->testOverlap(*b_, b_in_a, stats);
    }
    std::size_t all(const Pose& b_in_a, collision::BvhQueryStats* stats,
                    std::vector<collision::TrianglePair>* pairs) override {
        std::vector<collision::TrianglePair> found = a_->intersect(*b_, b_in_a, stats);
        const std::size_t n = found.size();
        if (pairs) *pairs = std::move(found);
        return n;
    }
    collision::MeshBvh* treeA() override { return a_.get(); }
    const collision::MeshBvh* treeB() const override { return b_.get(); }

private:
    std::string_view bv_;
    collision::BvhBuild how_;
    std::unique_ptr<collision::MeshBvh> a_;
    std::unique_ptr<collision::MeshBvh> b_;
};

#ifdef CDLAB_HAVE_FCL
template <class BV>
class FclMethod final : public NarrowMethod {
public:
    FclMethod(std::string name, fcl::detail::SplitMethodType split)
        : name_(std::move(name)), split_(split) {}
    std::string name() const override { return name_; }
    bool hasCounters() const override { return false; }
    void build(const TriangleMesh& mesh) override {
        std::vector<fcl::Vector3d> vertices;
        vertices.reserve(mesh.vertices.size());
        for (const Vec3& v : mesh.vertices) vertices.push_back(v.cast<double>());
        std::vector<fcl::Triangle> triangles;
        triangles.reserve(mesh.triangles.size());
        for (const auto& t : mesh.triangles) {
            triangles.emplace_back(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                                   static_cast<std::size_t>(t[2]));
        }
        auto make = [&] {
            auto model = std::make_shared<fcl::BVHModel<BV>>();
            model->bv_splitter = std::make_shared<fcl::detail::BVSplitter<BV>>(split_);
            model->beginModel();
            model->addSubModel(vertices, triangles);
            model->endModel();
            return model;
        };
        a_ = std::make_unique<fcl::CollisionObjectd>(make(), fcl::Transform3d::Identity());
        b_ = std::make_unique<fcl::CollisionObjectd>(make(), fcl::Transform3d::Identity());
    }
    bool first(const Pose& b_in_a, collision::BvhQueryStats*) override {
        return run(b_in_a, first_request_) > 0;
    }
    std::size_t all(const Pose& b_in_a, collision::BvhQueryStats*,
                    std::vector<collision::TrianglePair>*) override {
        return run(b_in_a, all_request_);
    }

private:
    // As an FCL user queries a moving object: the objects are made once (the constructor walks
    // every vertex for the local AABB), each query only sets B's transform. fcl::collide on two
    // BVH models reads neither object's world AABB, so computeAABB is not called.
    std::size_t run(const Pose& b_in_a, const fcl::CollisionRequestd& request) {
        fcl::Transform3d tf = fcl::Transform3d::Identity();
        tf.linear() = b_in_a.rotation().cast<double>();
        tf.translation() = b_in_a.position.cast<double>();
        b_->setTransform(tf);
        fcl::CollisionResultd result;
        if constexpr (std::is_same_v<BV, fcl::RSSd>) {
            // fcl::collide has no oriented dispatch for RSS (it copies and re-fits both models
            // per query, ~19 ms at 10k triangles); FCL's own RSS traversal node is the path its
            // tests use for RSS trees.
            fcl::detail::MeshCollisionTraversalNodeRSSd node;
            fcl::detail::initialize(node, rssModel(*a_), a_->getTransform(), rssModel(*b_),
                                    b_->getTransform(), request, result);
            fcl::detail::collide(&node);
        } else {
            fcl::collide(a_.get(), b_.get(), request, result);
        }
        return result.numContacts();
    }

    // No contact points or normals (enable_contact false: FCL stops at the triangle test);
    // first contact stops at one pair, all pairs never stops.
    const fcl::CollisionRequestd first_request_{1, false};
    const fcl::CollisionRequestd all_request_{std::numeric_limits<std::size_t>::max(), false};
    static const fcl::BVHModel<fcl::RSSd>& rssModel(const fcl::CollisionObjectd& o) {
        return static_cast<const fcl::BVHModel<fcl::RSSd>&>(*o.collisionGeometry());
    }

    std::string name_;
    fcl::detail::SplitMethodType split_;

    std::unique_ptr<fcl::CollisionObjectd> a_;
    std::unique_ptr<fcl::CollisionObjectd> b_;
};
#endif

std::unique_ptr<NarrowMethod> makeMethod(const std::string& name) {
    for (const std::string_view bv : collision::bvhVolumeNames()) {
        if (bv == name) return std::make_unique<CdlabMethod>(bv, collision::BvhBuild::TopDown);
        if (std::string(bv) + "-bu" == name) {
            return std::make_unique<CdlabMethod>(bv, collision::BvhBuild::BottomUp);
        }
    }
#ifdef CDLAB_HAVE_FCL
    // fcl-<volume>[-median|-center]: FCL's BVHModel with its split rule (default: mean).
    std::string base = name;
    fcl::detail::SplitMethodType split = fcl::detail::SPLIT_METHOD_MEAN;
    for (const auto& [suffix, method] : {std::pair<std::string_view, fcl::detail::SplitMethodType>{
                                             "-median", fcl::detail::SPLIT_METHOD_MEDIAN},
                                         {"-center", fcl::detail::SPLIT_METHOD_BV_CENTER}}) {
        if (base.ends_with(suffix)) {
            base.resize(base.size() - suffix.size());
            split = method;
        }
    }
    if (base == "fcl-obbrss") return std::make_unique<FclMethod<fcl::OBBRSSd>>(name, split);
    if (base == "fcl-obb") return std::make_unique<FclMethod<fcl::OBBd>>(name, split);
    if (base == "fcl-rss") return std::make_unique<FclMethod<fcl::RSSd>>(name, split);
    if (base == "fcl-kios") return std::make_unique<FclMethod<fcl::kIOSd>>(name, split);
    if (base == "fcl-aabb") return std::make_unique<FclMethod<fcl::AABBd>>(name, split);
    if (base == "fcl-kdop18") return std::make_unique<FclMethod<fcl::KDOPd<18>>>(name, split);
#endif
    return nullptr;
}

struct Row {
    std::string method;
    double build_ms = 0;  // one tree
    double first_us = 0;
    double all_us = 0;
    double first_nv = 0;
    double first_np = 0;
    double all_nv = 0;
    double all_np = 0;
    int bool_mismatches = 0;
    int count_mismatches = 0;
    bool counters = false;
    BvhUnitCosts unit;    // Cv, Cp (cdlab only)
    double refit_ms = 0;  // one tree refitted to the deformed torus (cdlab only)
    std::int32_t refit_nu = 0;
    bool refit_ok = true;  // the refitted tree's pairs equal the reference on the deformed torus
    // Each round's times, when there were several rounds (the fields above are their medians).
    std::vector<double> build_by_round;
    std::vector<double> first_by_round;
    std::vector<double> all_by_round;
};

// One row per method from every round's rows (same order): times the median over the rounds,
// mismatches the most any round saw, the refit checked in every round; the counts and unit costs
// are the first round's (the counts are the same in every round).
std::vector<Row> mergeRounds(const std::vector<std::vector<Row>>& by_round) {
    std::vector<Row> rows = by_round.front();
    for (std::size_t m = 0; m < rows.size(); ++m) {
        Row& row = rows[m];
        std::vector<double> refit;
        for (const std::vector<Row>& round : by_round) {
            const Row& r = round[m];
            row.build_by_round.push_back(r.build_ms);
            row.first_by_round.push_back(r.first_us);
            row.all_by_round.push_back(r.all_us);
            refit.push_back(r.refit_ms);
            row.bool_mismatches = std::max(row.bool_mismatches, r.bool_mismatches);
            row.count_mismatches = std::max(row.count_mismatches, r.count_mismatches);
            row.refit_ok = row.refit_ok && r.refit_ok;
        }
        row.build_ms = median(row.build_by_round);
        row.first_us = median(row.first_by_round);
        row.all_us = median(row.all_by_round);
        row.refit_ms = median(refit);
    }
    return rows;
}

// The torus deformed for the refit row: radial waves around the ring and a twist about z, moving
// vertices by up to ~20 % of the ring radius (more than a triangle's size, so leaves move).
TriangleMesh deformedTorus(const TriangleMesh& mesh) {
    TriangleMesh m = mesh;
    for (Vec3& v : m.vertices) {
        const Real angle = std::atan2(v.y(), v.x());
        const Real k = 1 + Real(0.15) * std::sin(3 * angle);
        const Real twist = Real(0.3) * v.z();
        const Vec3 w(v.x() * k, v.y() * k, v.z());
        v = Vec3(w.x() * std::cos(twist) - w.y() * std::sin(twist),
                 w.x() * std::sin(twist) + w.y() * std::cos(twist), w.z());
    }
    return m;
}

// Poses of B in A's frame from a fixed stream: B's centre uniform in [-1.6, 1.6]^3 (the tori's
// bounding boxes overlap), uniform rotation; the first poses/2 that collide and the first
// poses/2 that do not, by the brute-force answer computed here once per pose.
struct Workload {
    std::vector<Pose> poses;
    std::vector<std::vector<collision::TrianglePair>> answers;
};

Workload makeWorkload(const TriangleMesh& mesh, const collision::MeshBvh& tree, int count,
                      std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<Real> unit(0, 1);
    Workload w;
    int hits = 0;
    int misses = 0;
    const int half = count / 2;
    for (int guard = 0; (hits < half || misses < half) && guard < 100 * count; ++guard) {
        Pose p;
        p.position = Vec3(unit(rng), unit(rng), unit(rng)) * Real(3.2) - Vec3::Constant(1.6);
        // Shoemake's uniform rotation.
        const Real u1 = unit(rng);
        const Real u2 = 2 * std::numbers::pi_v<Real> * unit(rng);
        const Real u3 = 2 * std::numbers::pi_v<Real> * unit(rng);
        const Real a = std::sqrt(1 - u1);
        const Real b = std::sqrt(u1);
        p.orientation =
            collision::Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3))
                .normalized();
        // Classify with the tree (cheap); the brute force below is the reference.
        const bool hit = tree.testOverlap(tree, p);
        if ((hit && hits >= half) || (!hit && misses >= half)) continue;
        (hit ? hits : misses) += 1;
        w.poses.push_back(p);
        // The brute force up to 10k x 10k triangles; beyond, its sweep form (the same list,
        // tested equal to it in bvh_test).
        const bool small = mesh.triangles.size() <= 20000;
        w.answers.push_back(small ? collision::intersectMeshMeshBruteForce(mesh, mesh, p)
                                  : collision::intersectMeshMeshSweep(mesh, mesh, p));
    }
    return w;
}

}  // namespace

std::vector<std::string> narrowphaseBenchMethods() {
    std::vector<std::string> names(collision::bvhVolumeNames().begin(),
                                   collision::bvhVolumeNames().end());
#ifdef CDLAB_HAVE_FCL
    for (const char* n :
         {"fcl-obbrss", "fcl-obb", "fcl-rss", "fcl-kios", "fcl-aabb", "fcl-kdop18"}) {
        names.emplace_back(n);
    }
#endif
    return names;
}

namespace {

// One method on the workload: build time, first-contact and all-pairs queries at every pose
// (fastest of `reps`), their node and triangle tests, mismatches against the brute force, and
// for cdlab's trees the unit costs and a refit to the deformed torus.
Row measureMethod(const std::string& n, const TriangleMesh& mesh, const Workload& w,
                  const TriangleMesh& deformed,
                  const std::vector<collision::TrianglePair>& deformed_answer, int reps) {
    const auto n_poses = static_cast<int>(w.poses.size());
    std::unique_ptr<NarrowMethod> method = makeMethod(n);
    Row row;
    row.method = n;
    row.counters = method->hasCounters();
    double best_build = std::numeric_limits<double>::infinity();
    for (int r = 0; r < std::min(reps, 3); ++r) {
        const double t = threadCpuSeconds();
        method->build(mesh);
        best_build = std::min(best_build, secondsSince(t) / 2);  // two trees built
    }
    row.build_ms = 1e3 * best_build;
    std::vector<collision::TrianglePair> pairs;
    for (int i = 0; i < n_poses; ++i) {
        const Pose& p = w.poses[static_cast<std::size_t>(i)];
        const auto& expected = w.answers[static_cast<std::size_t>(i)];
        double best_first = std::numeric_limits<double>::infinity();
        double best_all = std::numeric_limits<double>::infinity();
        collision::BvhQueryStats first_stats;
        collision::BvhQueryStats all_stats;
        bool hit = false;
        std::size_t count = 0;
        for (int r = 0; r < reps; ++r) {
            collision::BvhQueryStats s1;
            double t = threadCpuSeconds();
            hit = method->first(p, &s1);
            best_first = std::min(best_first, secondsSince(t));
            collision::BvhQueryStats s2;
            t = threadCpuSeconds();
            count = method->all(p, &s2, r == 0 ? &pairs : nullptr);
            best_all = std::min(best_all, secondsSince(t));
            first_stats = s1;
            all_stats = s2;
        }
        row.first_us += 1e6 * best_first / n_poses;
        row.all_us += 1e6 * best_all / n_poses;
        row.first_nv += static_cast<double>(first_stats.bv_tests) / n_poses;
        row.first_np += static_cast<double>(first_stats.triangle_tests) / n_poses;
        row.all_nv += static_cast<double>(all_stats.bv_tests) / n_poses;
        row.all_np += static_cast<double>(all_stats.triangle_tests) / n_poses;
        row.bool_mismatches += hit != !expected.empty();
        row.count_mismatches += count != expected.size();
        if (row.counters && pairs != expected) {
            ++row.count_mismatches;  // same count but another list: still wrong
        }
    }
    if (row.counters) {
        // Cv and Cp from the tests the all-pairs queries made at these poses, replayed
        // outside the timed queries above.
        row.unit = measureBvhUnitCosts(*method->treeA(), *method->treeB(), w.poses);
        // Refit A to the deformed torus (fastest of the repetitions; a refit of an already
        // refitted tree does the same work), then check its answer at the first pose.
        double best_refit = std::numeric_limits<double>::infinity();
        for (int r = 0; r < std::min(reps, 3); ++r) {
            const double t = threadCpuSeconds();
            row.refit_nu = method->treeA()->refit(deformed);
            best_refit = std::min(best_refit, secondsSince(t));
        }
        row.refit_ms = 1e3 * best_refit;
        row.refit_ok =
            method->treeA()->intersect(*method->treeB(), w.poses.front()) == deformed_answer;
    }
    return row;
}

void printRows(const std::vector<Row>& rows, std::ostream& out) {
    out << std::left << std::setw(18) << "method" << std::right << std::setw(10) << "build_ms"
        << std::setw(11) << "first_us" << std::setw(11) << "all_us" << std::setw(11) << "first_Nv"
        << std::setw(10) << "first_Np" << std::setw(11) << "all_Nv" << std::setw(10) << "all_Np"
        << std::setw(8) << "Cv_ns" << std::setw(8) << "Cp_ns" << std::setw(10) << "refit_ms"
        << std::setw(8) << "Nu" << std::setw(11) << "bool_diff" << std::setw(11) << "pair_diff"
        << '\n';
    out << std::fixed;
    for (const Row& r : rows) {
        out << std::left << std::setw(18) << r.method << std::right << std::setprecision(2)
            << std::setw(10) << r.build_ms << std::setprecision(1) << std::setw(11) << r.first_us
            << std::setw(11) << r.all_us;
        if (r.counters) {
            out << std::setprecision(0) << std::setw(11) << r.first_nv << std::setw(10)
                << r.first_np << std::setw(11) << r.all_nv << std::setw(10) << r.all_np
                << std::setprecision(1);
            if (r.unit.measured) {
                out << std::setw(8) << r.unit.bv_test_ns << std::setw(8)
                    << r.unit.triangle_test_ns;
            } else {
                out << std::setw(8) << "-" << std::setw(8) << "-";
            }
            out << std::setprecision(2) << std::setw(10) << r.refit_ms << std::setw(8)
                << r.refit_nu;
        } else {
            out << std::setw(11) << "-" << std::setw(10) << "-" << std::setw(11) << "-"
                << std::setw(10) << "-" << std::setw(8) << "-" << std::setw(8) << "-"
                << std::setw(10) << "-" << std::setw(8) << "-";
        }
        out << std::setw(11) << r.bool_mismatches << std::setw(11) << r.count_mismatches << '\n';
    }
    out.unsetf(std::ios::fixed);
    out << "(Cv, Cp: ns per BV test and per triangle test, timed by replaying the tests the "
           "all-pairs"
           " queries made; refit: one tree to a deformed torus, Nu nodes updated)\n";
    bool unmeasured = false;
    for (const Row& r : rows) unmeasured = unmeasured || (r.counters && !r.unit.measured);
    if (unmeasured) out << "(" << kUnmeasuredUnitCostsNote << ")\n";
}

// The fastest cdlab row and the fastest FCL row of one column, and their ratio.
struct Best {
    const Row* cdlab = nullptr;
    const Row* fcl = nullptr;
    double ratio() const { return cdlab && fcl ? value(*cdlab) / value(*fcl) : 0; }
    double (*value)(const Row&) = nullptr;
};

Best bestOf(const std::vector<Row>& rows, double (*value)(const Row&)) {
    Best b;
    b.value = value;
    for (const Row& r : rows) {
        const Row*& slot = r.counters ? b.cdlab : b.fcl;
        if (!slot || value(r) < value(*slot)) slot = &r;
    }
    return b;
}

// One line per column: cdlab's fastest volume against FCL's fastest, as a ratio (below 1:
// cdlab faster), and with several rounds each round's ratio of its own fastest. Printed only
// when both libraries ran.
void printBest(const std::vector<Row>& rows, const std::vector<std::vector<Row>>& by_round,
               std::ostream& out) {
    const std::pair<const char*, double (*)(const Row&)> columns[] = {
        {"build", [](const Row& r) { return r.build_ms; }},
        {"first contact", [](const Row& r) { return r.first_us; }},
        {"all pairs", [](const Row& r) { return r.all_us; }}};
    for (const auto& [label, value] : columns) {
        const Best b = bestOf(rows, value);
        if (!b.cdlab || !b.fcl) return;
        out << std::fixed << std::setprecision(2) << "best " << label << ": cdlab "
            << b.cdlab->method << ' ' << value(*b.cdlab) << ", FCL " << b.fcl->method << ' '
            << value(*b.fcl) << ", ratio " << b.ratio();
        if (by_round.size() > 1) {
            out << " (by round:";
            for (const std::vector<Row>& round : by_round) {
                out << ' ' << bestOf(round, value).ratio();
            }
            out << ')';
        }
        out << '\n';
        out.unsetf(std::ios::fixed);
        out << std::setprecision(6);
    }
}

nlohmann::json rowsJson(const std::vector<Row>& rows) {
    nlohmann::json arr = nlohmann::json::array();
    for (const Row& r : rows) {
        nlohmann::json o{{"method", r.method},
                         {"library", r.counters ? "cdlab" : "fcl"},
                         {"build_ms", r.build_ms},
                         {"first_us", r.first_us},
                         {"all_us", r.all_us},
                         {"bool_mismatches", r.bool_mismatches},
                         {"pair_mismatches", r.count_mismatches}};
        if (!r.first_by_round.empty()) {
            o["build_ms_by_round"] = r.build_by_round;
            o["first_us_by_round"] = r.first_by_round;
            o["all_us_by_round"] = r.all_by_round;
        }
        if (r.counters) {
            o["first_nv"] = r.first_nv;
            o["first_np"] = r.first_np;
            o["all_nv"] = r.all_nv;
            o["all_np"] = r.all_np;
            // null when not measured (BvhUnitCosts::measured).
            o["bv_test_ns"] = r.unit.measured ? nlohmann::json(r.unit.bv_test_ns) : nullptr;
            o["triangle_test_ns"] =
                r.unit.measured ? nlohmann::json(r.unit.triangle_test_ns) : nullptr;
            o["bv_tests_timed"] = r.unit.bv_tests_timed;
            o["triangle_tests_timed"] = r.unit.triangle_tests_timed;
            o["triangle_tests_from_queries"] = r.unit.triangles_from_queries;
            o["refit_ms"] = r.refit_ms;
            o["refit_nu"] = r.refit_nu;
            o["refit_ok"] = r.refit_ok;
        }
        arr.push_back(o);
    }
    return arr;
}

}  // namespace

int runBenchNarrowphase(const BenchNarrowphaseOptions& options, std::ostream& out,
                        std::ostream& err) {
    if (options.poses < 2 || options.poses % 2 != 0) {
        err << "cdlab bench narrowphase: --poses must be even and >= 2\n";
        return 2;
    }
    if (options.reps < 1) {
        err << "cdlab bench narrowphase: --reps must be >= 1\n";
        return 2;
    }
    if (options.rounds < 1 || options.rounds > kMaxBenchRounds) {
        err << "cdlab bench narrowphase: --rounds must be in 1.." << kMaxBenchRounds << "\n";
        return 2;
    }
    const int target = options.large ? 100000 : options.triangles;
    if (target < 32) {
        err << "cdlab bench narrowphase: --triangles must be >= 32\n";
        return 2;
    }
    std::vector<std::string> names =
        options.methods.empty() ? narrowphaseBenchMethods() : options.methods;
    for (const std::string& n : names) {
        if (!makeMethod(n)) {
            err << "cdlab bench narrowphase: unknown method '" << n << "' (expected one of:";
            for (const std::string& m : narrowphaseBenchMethods()) err << ' ' << m;
            err << "; a volume name with -bu: its bottom-up build)\n";
            return 2;
        }
    }
    // 2 nu nv triangles with nu = 2 nv.
    const int nv = std::max(4, static_cast<int>(std::lround(std::sqrt(target / 4.0))));
    const TriangleMesh mesh = makeTorus(2 * nv, nv);
    const auto classify = collision::buildMeshBvh("obb", mesh);
    const Workload w = makeWorkload(mesh, *classify, options.poses, options.seed);
    const auto n_poses = static_cast<int>(w.poses.size());
    int colliding = 0;
    for (const auto& a : w.answers) colliding += a.empty() ? 0 : 1;
    out << "narrowphase: two tori of " << mesh.triangles.size() << " triangles, " << n_poses
        << " poses (" << colliding << " colliding), fastest of " << options.reps
        << " repetitions per pose";
    if (options.rounds > 1) {
        out << ", times the median of " << options.rounds
            << " rounds (methods in order, then in reverse, in turn)";
    }
    out << '\n';

    // The refit workload: the deformed torus as A, the reference its sweep answer at pose 0.
    const TriangleMesh deformed = deformedTorus(mesh);
    const std::vector<collision::TrianglePair> deformed_answer =
        collision::intersectMeshMeshSweep(deformed, mesh, w.poses.front());

    std::vector<std::vector<Row>> by_round;
    for (int round = 0; round < options.rounds; ++round) {
        std::vector<Row> rows(names.size());
        for (std::size_t k = 0; k < names.size(); ++k) {
            const std::size_t m = round % 2 == 0 ? k : names.size() - 1 - k;
            rows[m] = measureMethod(names[m], mesh, w, deformed, deformed_answer, options.reps);
        }
        by_round.push_back(std::move(rows));
    }
    const std::vector<Row> rows =
        options.rounds > 1 ? mergeRounds(by_round) : by_round.front();
    bool cdlab_wrong = false;
    for (const Row& row : rows) {
        if (row.counters &&
            (row.bool_mismatches > 0 || row.count_mismatches > 0 || !row.refit_ok)) {
            cdlab_wrong = true;
        }
    }

    printRows(rows, out);
    printBest(rows, by_round, out);

    if (options.json) {
        nlohmann::json j;
        j["triangles"] = mesh.triangles.size();
        j["poses"] = n_poses;
        j["colliding_poses"] = colliding;
        j["reps"] = options.reps;
        j["rounds"] = options.rounds;
        j["seed"] = options.seed;
        j["rows"] = rowsJson(rows);
        if (!writeTextReporting(*options.json, j.dump(2) + "\n", err)) return 1;
    }
    if (cdlab_wrong) {
        err << "cdlab bench narrowphase: a cdlab method disagrees with the brute force\n";
        return 1;
    }
    return 0;
}

}  // namespace app

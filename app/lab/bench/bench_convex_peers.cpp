// app/lab/bench/bench_convex_peers.cpp -- Bullet as the peer of `cdlab bench convex`
// (bench_convex_peers.h). Invariant: Bullet gets the pairs' exact geometry and runs unmodified
// library code; the dispatcher path calls processCollision as btCollisionDispatcher's
// defaultNearCallback does (wrappers and a btManifoldResult made per call), with the result's
// closest-point threshold raised as btCollisionWorld::contactPairTest raises it, and records
// the contact points instead of merging them into the persistent manifold (cdlab's contact()
// keeps no manifold either).
#include "bench_convex_peers.h"

#ifdef CDLAB_HAVE_BULLET
#include <BulletCollision/CollisionDispatch/btBoxBoxCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btConvexConvexAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionDispatch/btSphereBoxCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btSphereSphereCollisionAlgorithm.h>
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

using collision::Pose;
using collision::Quat;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

#ifdef CDLAB_HAVE_BULLET

namespace {

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

Vec3 toVec(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

// Bullet reports the normal on B (pointing from B to A), the point on B and the signed
// distance; point on A = point on B + normal * distance. cdlab's normal points from A to B.
ContactAnswer fromBullet(const btVector3& normal_on_b, const btVector3& point_on_b,
                         btScalar distance, bool swapped) {
    ContactAnswer out;
    out.signed_distance = distance;
    const Vec3 n = toVec(normal_on_b);
    const Vec3 on_b = toVec(point_on_b);
    const Vec3 on_other = on_b + distance * n;
    // Swapped: Bullet's B is our A.
    out.normal = swapped ? n : Vec3(-n);
    out.point_a = swapped ? on_b : on_other;
    out.point_b = swapped ? on_other : on_b;
    return out;
}

// Keeps the deepest contact point the algorithm reports.
class RecordingResult : public btManifoldResult {
public:
    RecordingResult(const btCollisionObjectWrapper* a, const btCollisionObjectWrapper* b)
        : btManifoldResult(a, b) {
        m_closestPointDistanceThreshold = BT_LARGE_FLOAT;
    }
    void addContactPoint(const btVector3& normal_on_b, const btVector3& point_on_b,
                         btScalar depth) override {
        if (!(depth >= best.signed_distance)) {  // also replaces the initial NaN
            const bool swapped = m_manifoldPtr->getBody0() != m_body0Wrap->getCollisionObject();
            best = fromBullet(normal_on_b, point_on_b, depth, swapped);
        }
    }
    ContactAnswer best;
};

std::string algorithmName(const btCollisionAlgorithm* algorithm, const Shape& a, const Shape& b) {
    if (dynamic_cast<const btBoxBoxCollisionAlgorithm*>(algorithm)) return "btBoxBoxDetector";
    if (dynamic_cast<const btSphereSphereCollisionAlgorithm*>(algorithm)) return "btSphereSphere";
    if (dynamic_cast<const btSphereBoxCollisionAlgorithm*>(algorithm)) return "btSphereBox(disabled)";
    if (dynamic_cast<const btConvexConvexAlgorithm*>(algorithm)) {
        const bool capsules = (a.type == ShapeType::Capsule || a.type == ShapeType::Sphere) &&
                              (b.type == ShapeType::Capsule || b.type == ShapeType::Sphere);
        return capsules ? "capsuleCapsuleDistance" : "btConvexConvex(GJK+EPA)";
    }
    return "other";
}

}  // namespace

struct BulletConvexPeer::State {
    BulletPath path = BulletPath::GeneralGjkEpa;
    std::vector<std::unique_ptr<btConvexShape>> shapes_a;
    std::vector<std::unique_ptr<btConvexShape>> shapes_b;
    std::vector<btTransform> poses_a;
    std::vector<btTransform> poses_b;
    // Dispatcher paths: one algorithm for the row (every pair has the same shape types) and one
    // pair of collision objects; each query passes its pair's shapes and transforms through the
    // wrappers, which is all the algorithms read, so the peer touches no per-pair state beyond
    // what cdlab's query reads.
    std::unique_ptr<btDefaultCollisionConfiguration> config;
    std::unique_ptr<btCollisionDispatcher> dispatcher;
    btCollisionObject object_a;
    btCollisionObject object_b;
    btCollisionAlgorithm* algorithm = nullptr;
    bool owned = false;  ///< made with new (SphereBoxAlgorithm), not by the dispatcher
    btDispatcherInfo info;
    std::string name = "btGjkPairDetector+EPA";

    ~State() {
        if (algorithm == nullptr) return;
        if (owned) {
            delete algorithm;
            return;
        }
        algorithm->~btCollisionAlgorithm();
        dispatcher->freeCollisionAlgorithm(algorithm);
    }
};

bool bulletAvailable() { return true; }

BulletConvexPeer::BulletConvexPeer(BulletPath path, const std::vector<ConvexPair>& pairs)
    : state_(std::make_unique<State>()) {
    State& s = *state_;
    s.path = path;
    for (const ConvexPair& p : pairs) {
        s.shapes_a.push_back(bulletShape(p.a));
        s.shapes_b.push_back(bulletShape(p.b));
        s.poses_a.push_back(bulletTransform(p.pose_a));
        s.poses_b.push_back(bulletTransform(p.pose_b));
    }
    if (path == BulletPath::GeneralGjkEpa || pairs.empty()) return;
    s.config = std::make_unique<btDefaultCollisionConfiguration>();
    s.dispatcher = std::make_unique<btCollisionDispatcher>(s.config.get());
    s.object_a.setCollisionShape(s.shapes_a[0].get());
    s.object_b.setCollisionShape(s.shapes_b[0].get());
    const btCollisionObjectWrapper wa(nullptr, s.shapes_a[0].get(), &s.object_a, s.poses_a[0], -1,
                                      -1);
    const btCollisionObjectWrapper wb(nullptr, s.shapes_b[0].get(), &s.object_b, s.poses_b[0], -1,
                                      -1);
    if (path == BulletPath::SphereBoxAlgorithm) {
        btCollisionAlgorithmConstructionInfo ci;
        ci.m_dispatcher1 = s.dispatcher.get();
        s.algorithm = new btSphereBoxCollisionAlgorithm(nullptr, ci, &wa, &wb, false);
        s.owned = true;
    } else {
        s.algorithm = s.dispatcher->findAlgorithm(&wa, &wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
    }
    s.name = algorithmName(s.algorithm, pairs[0].a, pairs[0].b);
}

BulletConvexPeer::~BulletConvexPeer() = default;

std::string BulletConvexPeer::pathName() const { return state_->name; }

ContactAnswer BulletConvexPeer::query(std::size_t i) const {
    const State& s = *state_;
    if (s.path != BulletPath::GeneralGjkEpa) {
        const btCollisionObjectWrapper wa(nullptr, s.shapes_a[i].get(), &s.object_a, s.poses_a[i],
                                          -1, -1);
        const btCollisionObjectWrapper wb(nullptr, s.shapes_b[i].get(), &s.object_b, s.poses_b[i],
                                          -1, -1);
        RecordingResult result(&wa, &wb);
        s.algorithm->processCollision(&wa, &wb, s.info, &result);
        return result.best;
    }
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver depth_solver;
    btGjkPairDetector detector(s.shapes_a[i].get(), s.shapes_b[i].get(), &simplex, &depth_solver);
    btGjkPairDetector::ClosestPointInput in;
    in.m_transformA = s.poses_a[i];
    in.m_transformB = s.poses_b[i];
    btPointCollector result;
    detector.getClosestPoints(in, result, nullptr);
    if (!result.m_hasResult) return ContactAnswer{};
    return fromBullet(result.m_normalOnBInWorld, result.m_pointInWorld, result.m_distance, false);
}

#else

struct BulletConvexPeer::State {};

bool bulletAvailable() { return false; }

BulletConvexPeer::BulletConvexPeer(BulletPath, const std::vector<ConvexPair>&)
    : state_(std::make_unique<State>()) {}

BulletConvexPeer::~BulletConvexPeer() = default;

std::string BulletConvexPeer::pathName() const { return "n/a"; }

ContactAnswer BulletConvexPeer::query(std::size_t) const { return ContactAnswer{}; }

#endif

}  // namespace app

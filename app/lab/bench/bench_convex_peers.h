// app/lab/bench/bench_convex_peers.h -- the pairs of `cdlab bench convex` and the Bullet peers that
// answer them: Bullet's own narrow phase (the collision algorithm its default dispatcher picks
// for the pair: btBoxBoxDetector, the sphere-sphere and sphere-box algorithms, the capsule special
// cases of btConvexConvexAlgorithm) and its general btGjkPairDetector + EPA. Bullet's headers
// stay in bench_convex_peers.cpp (CDLAB_HAVE_BULLET).
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace app {

struct ConvexPair {
    collision::Shape a;
    collision::Shape b;
    collision::Pose pose_a;
    collision::Pose pose_b;
    collision::Real scale = 1;  ///< larger bounding radius
};

/// One library's answer to a pair, world frame, in cdlab's convention (contact.h): the signed
/// distance (negative: minus the depth; NaN: no answer), the unit normal from A towards B and
/// the witness points on A and B. A peer reporting several contact points gives its deepest.
struct ContactAnswer {
    collision::Real signed_distance = std::numeric_limits<collision::Real>::quiet_NaN();
    collision::Vec3 normal = collision::Vec3::Zero();
    collision::Vec3 point_a = collision::Vec3::Zero();
    collision::Vec3 point_b = collision::Vec3::Zero();
};

enum class BulletPath {
    /// btGjkPairDetector with btGjkEpaPenetrationDepthSolver on the two shapes: Bullet's
    /// general convex query (distance when apart, EPA depth when overlapping).
    GeneralGjkEpa,
    /// The collision algorithm btCollisionDispatcher finds for the pair with
    /// btDefaultCollisionConfiguration, run by processCollision as Bullet's narrow phase runs it
    /// every step. Its contact points are recorded without the persistent manifold's cache.
    Dispatcher,
    /// btSphereBoxCollisionAlgorithm made directly: the sphere-box closed form Bullet ships but
    /// leaves out of btDefaultCollisionConfiguration (USE_BUGGY_SPHERE_BOX_ALGORITHM), whose
    /// dispatcher runs btConvexConvexAlgorithm for sphere-box instead. Sphere A, box B.
    SphereBoxAlgorithm,
};

/// True when cdlab was built with Bullet.
bool bulletAvailable();

/// Bullet's shapes (zero margins for boxes and hulls: the exact geometry; spheres and capsules
/// keep their radius as margin, which is their geometry) and per-pair state for one path,
/// built once; query(i) is the timed part.
class BulletConvexPeer {
public:
    BulletConvexPeer(BulletPath path, const std::vector<ConvexPair>& pairs);
    ~BulletConvexPeer();
    BulletConvexPeer(const BulletConvexPeer&) = delete;
    BulletConvexPeer& operator=(const BulletConvexPeer&) = delete;

    ContactAnswer query(std::size_t i) const;
    /// What ran: "btGjkPairDetector+EPA", or the dispatcher's algorithm for the first pair
    /// ("btBoxBoxDetector", "btSphereSphere", "capsuleCapsuleDistance", "btConvexConvex(GJK+EPA)",
    /// "btSphereBox(disabled)").
    std::string pathName() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace app

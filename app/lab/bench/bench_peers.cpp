// app/lab/bench/bench_peers.cpp -- Bullet and FCL broad phases behind the benchmark interface.
// Compiled in only when CMake found them (CDLAB_HAVE_BULLET, CDLAB_HAVE_FCL); their headers stay
// in this file. Every peer gets the same doubles as cdlab: box i is centre_i -/+ half_i.
//  - Bullet is driven directly (createProxy, setAabb, calculateOverlappingPairs) with its own
//    hashed pair cache and no dispatcher, which it only needs to free narrow-phase algorithms.
//    Its cache is a superset of the exact pairs (btDbvtBroadphase keeps pairs while the fattened
//    leaves overlap and removes stale ones lazily; btAxisSweep3 tests quantised boxes), so
//    deliverExact() filters it into a list of exact pairs (timed under the exact-pairs rule) and
//    summary() filters it again for the check, untimed.
//  - FCL's managers call back exactly for AABB-overlapping pairs; the callback only counts them.
//    Its CollisionObject AABB for an unrotated Box is translation -/+ side/2, i.e. the same
//    doubles as cdlab's box.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "bench_method.h"

#ifdef CDLAB_HAVE_BULLET
#include <BulletCollision/BroadphaseCollision/btAxisSweep3.h>
#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <LinearMath/btAabbUtil2.h>
#endif

#ifdef CDLAB_HAVE_FCL
#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>
#endif

namespace app {

namespace {

[[maybe_unused]] void addExactPair(const MovingBoxes& boxes, int a, int b, PairSummary& out) {
    if (a == b || a < 0 || b < 0) return;
    if (a > b) std::swap(a, b);
    if (!boxes.aabb(a).overlaps(boxes.aabb(b))) return;
    ++out.pairs;
    out.hash += pairHash(a, b);
}

#ifdef CDLAB_HAVE_BULLET

enum class BulletKind { Dbvt, DbvtDeferred, AxisSweep, AxisSweepRaycast };

/// A tunable Bullet configuration. DBVT: the leaf fattening margin (Bullet's global gDbvtMargin,
/// default 0.05 in scene units) as a fraction of the workload's mean box size, negative for
/// Bullet's default; the velocity prediction m_prediction (default 0). Axis sweep: the world
/// box handed to the quantiser as a multiple of the workload's cube about its centre, and 16-
/// or 32-bit handles (quantisation to 2^16 or 2^32 steps).
struct BulletTuning {
    double margin_fraction = -1;
    double prediction = 0;
    double world_scale = 1;
    int handle_bits = 0;  ///< 0: 16-bit below 16k boxes, 32-bit from there (the default)
};

constexpr btScalar kBulletDefaultMargin = btScalar(0.05);

// btScalar may be float (Bullet built in single precision): round outwards so the proxy's box
// contains the exact one and Bullet's pair cache stays a superset of the exact pairs.
btScalar roundDown(collision::Real x) {
    btScalar s = static_cast<btScalar>(x);
    if (static_cast<collision::Real>(s) > x)
        s = std::nextafter(s, -std::numeric_limits<btScalar>::infinity());
    return s;
}
btScalar roundUp(collision::Real x) {
    btScalar s = static_cast<btScalar>(x);
    if (static_cast<collision::Real>(s) < x)
        s = std::nextafter(s, std::numeric_limits<btScalar>::infinity());
    return s;
}
btVector3 lowerCorner(const collision::Aabb& box) {
    return btVector3(roundDown(box.min.x()), roundDown(box.min.y()), roundDown(box.min.z()));
}
btVector3 upperCorner(const collision::Aabb& box) {
    return btVector3(roundUp(box.max.x()), roundUp(box.max.y()), roundUp(box.max.z()));
}

class BulletMethod : public BenchMethod {
public:
    explicit BulletMethod(BulletKind kind, BulletTuning tuning = {})
        : kind_(kind), tuning_(tuning) {}
    ~BulletMethod() override {
        // btDbvtBroadphase allocates each proxy; the axis sweeps keep theirs in one array.
        if (kind_ == BulletKind::Dbvt || kind_ == BulletKind::DbvtDeferred) {
            for (btBroadphaseProxy* p : proxies_) broad_phase_->destroyProxy(p, nullptr);
        }
        gDbvtMargin = kBulletDefaultMargin;
    }

    void insertAll(const MovingBoxes& boxes,
                   std::span<const collision::ProxyVolumes> /*volumes*/) override {
        const int n = boxes.size();
        const double centre = boxes.lower() + boxes.side() / 2;
        const double half = tuning_.world_scale * boxes.side() / 2;
        const btVector3 world_min = btVector3(1, 1, 1) * roundDown(centre - half);
        const btVector3 world_max = btVector3(1, 1, 1) * roundUp(centre + half);
        switch (kind_) {
            case BulletKind::Dbvt:
            case BulletKind::DbvtDeferred: {
                double mean_size = 0;
                for (const collision::Vec3& h : boxes.halfExtents()) mean_size += 2 * h.mean();
                mean_size /= n;
                margin_ = tuning_.margin_fraction < 0
                              ? kBulletDefaultMargin
                              : btScalar(tuning_.margin_fraction * mean_size);
                gDbvtMargin = margin_;
                auto dbvt = std::make_unique<btDbvtBroadphase>();
                dbvt->m_deferedcollide = kind_ == BulletKind::DbvtDeferred;
                dbvt->m_prediction = btScalar(tuning_.prediction);
                broad_phase_ = std::move(dbvt);
                break;
            }
            case BulletKind::AxisSweep:
            case BulletKind::AxisSweepRaycast: {
                // The raycast accelerator is a second broad phase (a btDbvtBroadphase) that the
                // sweep keeps up to date for ray queries; pair finding does not need it.
                const bool no_raycast = kind_ == BulletKind::AxisSweep;
                const bool small = tuning_.handle_bits == 0 ? n < 16000 : tuning_.handle_bits == 16;
                if (small) {
                    broad_phase_ = std::make_unique<btAxisSweep3>(
                        world_min, world_max, static_cast<unsigned short>(n + 2), nullptr,
                        no_raycast);
                } else {
                    broad_phase_ = std::make_unique<bt32BitAxisSweep3>(
                        world_min, world_max, static_cast<unsigned int>(n + 2), nullptr,
                        no_raycast);
                }
                break;
            }
        }
        proxies_.resize(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
            const collision::Aabb box = boxes.aabb(i);
            proxies_[i] = broad_phase_->createProxy(
                lowerCorner(box), upperCorner(box), BOX_SHAPE_PROXYTYPE,
                reinterpret_cast<void*>(static_cast<std::intptr_t>(i)),
                int(btBroadphaseProxy::DefaultFilter), int(btBroadphaseProxy::AllFilter), nullptr);
        }
    }
    void moveAll(const MovingBoxes& boxes,
                 std::span<const collision::ProxyVolumes> /*volumes*/) override {
        // gDbvtMargin is a global of Bullet's, read whenever a DBVT leaf is (re)inserted: with
        // several instances alive at once (bench broadphase --interleave), the last one made
        // would set every one's margin. Each sets its own before its calls.
        gDbvtMargin = margin_;
        for (std::size_t i = 0; i < proxies_.size(); ++i) {
            const collision::Aabb box = boxes.aabb(static_cast<int>(i));
            broad_phase_->setAabb(proxies_[i], lowerCorner(box), upperCorner(box), nullptr);
        }
    }
    void findPairs() override {
        gDbvtMargin = margin_;
        broad_phase_->calculateOverlappingPairs(nullptr);
    }
    PairSummary summary(const MovingBoxes& boxes) override {
        PairSummary out;
        btBroadphasePairArray& cache =
            broad_phase_->getOverlappingPairCache()->getOverlappingPairArray();
        raw_pairs_ = cache.size();
        for (int k = 0; k < cache.size(); ++k) {
            const btBroadphasePair& p = cache[k];
            if (p.m_pProxy0 == nullptr || p.m_pProxy1 == nullptr) continue;
            addExactPair(
                boxes,
                static_cast<int>(reinterpret_cast<std::intptr_t>(p.m_pProxy0->m_clientObject)),
                static_cast<int>(reinterpret_cast<std::intptr_t>(p.m_pProxy1->m_clientObject)),
                out);
        }
        // The list deliverExact() made, when it ran for this frame, must be the same set: a
        // differing one is reported as a mismatch (the count made impossible).
        if (delivered_ && !(summarizePairs(exact_) == out)) out.pairs = -1;
        delivered_ = false;
        return out;
    }
    std::int64_t rawPairs() const override { return raw_pairs_; }
    void deliverExact(const MovingBoxes& boxes) override {
        // What a caller of Bullet does before its narrow phase: keep the cache pairs whose
        // boxes overlap, tested on the boxes the proxies hold (the exact ones when btScalar is
        // double; float proxies hold them rounded outward, so the workload's are tested then).
        // No sort: Bullet's order is its hash's, and none is asked of it.
        btBroadphasePairArray& cache =
            broad_phase_->getOverlappingPairCache()->getOverlappingPairArray();
        exact_.clear();
        delivered_ = true;
        for (int k = 0; k < cache.size(); ++k) {
            const btBroadphaseProxy* p0 = cache[k].m_pProxy0;
            const btBroadphaseProxy* p1 = cache[k].m_pProxy1;
            if (p0 == nullptr || p1 == nullptr) continue;
            int a = static_cast<int>(reinterpret_cast<std::intptr_t>(p0->m_clientObject));
            int b = static_cast<int>(reinterpret_cast<std::intptr_t>(p1->m_clientObject));
            bool overlap;
            if constexpr (sizeof(btScalar) == sizeof(collision::Real)) {
                overlap = TestAabbAgainstAabb2(p0->m_aabbMin, p0->m_aabbMax, p1->m_aabbMin,
                                               p1->m_aabbMax);
            } else {
                overlap = boxes.aabb(a).overlaps(boxes.aabb(b));
            }
            if (a > b) std::swap(a, b);
            if (overlap) exact_.push_back({a, b});
        }
    }

private:
    BulletKind kind_;
    BulletTuning tuning_;
    btScalar margin_ = kBulletDefaultMargin;  ///< this DBVT's gDbvtMargin
    std::unique_ptr<btBroadphaseInterface> broad_phase_;
    std::vector<btBroadphaseProxy*> proxies_;
    std::int64_t raw_pairs_ = 0;
    std::vector<collision::ProxyPair> exact_;  ///< deliverExact()'s list, reused
    bool delivered_ = false;                   ///< exact_ is this frame's
};

#endif  // CDLAB_HAVE_BULLET

#ifdef CDLAB_HAVE_FCL

enum class FclManager { Tree, SweepAndPrune };

/// How moved objects reach the manager after setTranslation + computeAABB.
enum class FclUpdate {
    Refit,       ///< update(): copy every AABB into the structure and refit it
    Update,      ///< update(all objects): each object re-placed, one rebalance
    UpdateEach,  ///< update(obj) per object: re-placed and rebalanced each time
    Reinsert,    ///< unregisterObject + registerObject per object
    Rebuild,     ///< clear + registerObjects (bulk build) every frame
};

bool countPair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* out = static_cast<PairSummary*>(data);
    int a = static_cast<int>(reinterpret_cast<std::intptr_t>(o1->getUserData()));
    int b = static_cast<int>(reinterpret_cast<std::intptr_t>(o2->getUserData()));
    if (a > b) std::swap(a, b);
    ++out->pairs;
    out->hash += pairHash(a, b);
    return false;  // keep going
}

class FclMethod : public BenchMethod {
public:
    /// init_level: DynamicAABBTreeCollisionManager::tree_init_level, how registerObjects builds
    /// the tree (0: top-down, FCL's default; 2: bottom-up on Morton codes).
    FclMethod(FclManager manager, FclUpdate update, int init_level = 0)
        : kind_(manager), update_(update), init_level_(init_level) {}

    void insertAll(const MovingBoxes& boxes,
                   std::span<const collision::ProxyVolumes> /*volumes*/) override {
        if (kind_ == FclManager::Tree) {
            auto tree = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
            tree->tree_init_level = init_level_;
            manager_ = std::move(tree);
        } else {
            manager_ = std::make_unique<fcl::SaPCollisionManagerd>();
        }
        const int n = boxes.size();
        objects_.reserve(static_cast<std::size_t>(n));
        raw_.reserve(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
            const fcl::Vector3d side = (2 * boxes.halfExtents()[i]).cast<double>();
            auto geometry = std::make_shared<fcl::Boxd>(side);
            fcl::Transform3d pose = fcl::Transform3d::Identity();
            pose.translation() = boxes.centers()[i].cast<double>();
            auto object = std::make_unique<fcl::CollisionObjectd>(geometry, pose);
            object->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(i)));
            raw_.push_back(object.get());
            objects_.push_back(std::move(object));
        }
        manager_->registerObjects(raw_);
        manager_->setup();
    }
    void moveAll(const MovingBoxes& boxes,
                 std::span<const collision::ProxyVolumes> /*volumes*/) override {
        for (std::size_t i = 0; i < raw_.size(); ++i) {
            raw_[i]->setTranslation(boxes.centers()[i].cast<double>());
            raw_[i]->computeAABB();
        }
        switch (update_) {
            case FclUpdate::Refit:
                manager_->update();
                break;
            case FclUpdate::Update:
                manager_->update(raw_);
                break;
            case FclUpdate::UpdateEach:
                for (fcl::CollisionObjectd* o : raw_) manager_->update(o);
                break;
            case FclUpdate::Reinsert:
                for (fcl::CollisionObjectd* o : raw_) {
                    manager_->unregisterObject(o);
                    manager_->registerObject(o);
                }
                break;
            case FclUpdate::Rebuild:
                manager_->clear();
                manager_->registerObjects(raw_);
                manager_->setup();
                break;
        }
    }
    void findPairs() override {
        found_ = PairSummary{};
        manager_->collide(&found_, countPair);
    }
    PairSummary summary(const MovingBoxes& /*boxes*/) override { return found_; }

private:
    FclManager kind_;
    FclUpdate update_;
    int init_level_;
    // The manager holds raw pointers to the objects: destroy it first.
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_;
    std::vector<fcl::CollisionObjectd*> raw_;
    std::unique_ptr<fcl::BroadPhaseCollisionManagerd> manager_;
    PairSummary found_;
};

#endif  // CDLAB_HAVE_FCL

[[maybe_unused]] std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%g", v);
    return buf;
}

#ifdef CDLAB_HAVE_BULLET
// The tuning grids. DBVT: margin 0 to 1 mean box size and Bullet's absolute default, deferred
// collide off and on, prediction 0 and 1 frame; axis sweep: world 1, 4 and 16 times the
// workload's cube, 16- and 32-bit handles.
void appendBulletGrid(std::vector<BenchMethodEntry>& methods, const std::string& sweep_skip) {
    const double margins[] = {-1, 0, 0.01, 0.05, 0.1, 0.3, 1};
    for (const bool deferred : {false, true}) {
        for (const double prediction : {0.0, 1.0}) {
            for (const double margin : margins) {
                BulletTuning t;
                t.margin_fraction = margin;
                t.prediction = prediction;
                BenchMethodEntry m;
                m.family = "bullet-dbvt";
                m.config = std::string("m") + (margin < 0 ? "default" : number(margin)) +
                           (deferred ? ":deferred" : "") +
                           (prediction != 0 ? ":p" + number(prediction) : "");
                m.name = m.family + ":" + m.config;
                m.description = "Bullet btDbvtBroadphase: gDbvtMargin " +
                                (margin < 0 ? std::string("0.05 (default)")
                                            : number(margin) + " x mean box size") +
                                ", m_deferedcollide " + (deferred ? "on" : "off") +
                                ", m_prediction " + number(prediction);
                m.peer = true;
                const BulletKind kind = deferred ? BulletKind::DbvtDeferred : BulletKind::Dbvt;
                m.create = [kind, t]() -> std::unique_ptr<BenchMethod> {
                    return std::make_unique<BulletMethod>(kind, t);
                };
                methods.push_back(std::move(m));
            }
        }
    }
    for (const int bits : {16, 32}) {
        for (const double scale : {1.0, 4.0, 16.0}) {
            BulletTuning t;
            t.world_scale = scale;
            t.handle_bits = bits;
            BenchMethodEntry m;
            m.family = "bullet-sap";
            m.config = "w" + number(scale) + ":q" + std::to_string(bits);
            m.name = m.family + ":" + m.config;
            m.description = std::string(bits == 16 ? "btAxisSweep3" : "bt32BitAxisSweep3") +
                            ", world " + number(scale) + " x the workload's cube";
            m.peer = true;
            m.default_max_n = 50000;
            m.skip_reason = sweep_skip;
            if (bits == 16) m.hard_max_n = 16000;
            m.create = [t]() -> std::unique_ptr<BenchMethod> {
                return std::make_unique<BulletMethod>(BulletKind::AxisSweep, t);
            };
            methods.push_back(std::move(m));
        }
    }
}
#endif

#ifdef CDLAB_HAVE_FCL
// FCL: every way of telling the manager about moved objects, with the tree built top-down
// (FCL's default) or bottom-up on Morton codes; the SaP manager updated or rebuilt.
void appendFclGrid(std::vector<BenchMethodEntry>& methods) {
    const std::pair<const char*, FclUpdate> updates[] = {
        {"refit", FclUpdate::Refit},           {"update", FclUpdate::Update},
        {"update-each", FclUpdate::UpdateEach}, {"reinsert", FclUpdate::Reinsert},
        {"rebuild", FclUpdate::Rebuild}};
    for (const int init_level : {0, 2}) {
        for (const auto& [update_name, update_kind] : updates) {
            const FclUpdate update = update_kind;  // a structured binding cannot be captured
            BenchMethodEntry m;
            m.family = "fcl-dtree";
            m.config = std::string(update_name) + ":init" + std::to_string(init_level);
            m.name = m.family + ":" + m.config;
            m.description = "FCL DynamicAABBTreeCollisionManager, " + std::string(update_name) +
                            ", tree_init_level " + std::to_string(init_level);
            m.peer = true;
            m.create = [update, init_level]() -> std::unique_ptr<BenchMethod> {
                return std::make_unique<FclMethod>(FclManager::Tree, update, init_level);
            };
            methods.push_back(std::move(m));
        }
    }
    for (const auto& [update_name, update_kind] :
         {std::pair<const char*, FclUpdate>{"update", FclUpdate::Update},
          std::pair<const char*, FclUpdate>{"rebuild", FclUpdate::Rebuild}}) {
        const FclUpdate update = update_kind;
        BenchMethodEntry m;
        m.family = "fcl-sap";
        m.config = update_name;
        m.name = m.family + ":" + m.config;
        m.description = "FCL SaPCollisionManager, " + std::string(update_name);
        m.peer = true;
        m.create = [update]() -> std::unique_ptr<BenchMethod> {
            return std::make_unique<FclMethod>(FclManager::SweepAndPrune, update);
        };
        methods.push_back(std::move(m));
    }
}
#endif

}  // namespace

void appendPeerMethods([[maybe_unused]] std::vector<BenchMethodEntry>& methods) {
#ifdef CDLAB_HAVE_BULLET
    auto bullet = [&](std::string name, std::string description, BulletKind kind, bool in_default,
                      int max_n, std::string reason) {
        BenchMethodEntry m;
        m.name = std::move(name);
        m.description = std::move(description);
        m.peer = true;
        m.default_set = in_default;
        m.default_max_n = max_n;
        m.skip_reason = std::move(reason);
        m.create = [kind]() -> std::unique_ptr<BenchMethod> {
            return std::make_unique<BulletMethod>(kind);
        };
        methods.push_back(std::move(m));
    };
    const std::string sweep_skip =
        "skipped: btAxisSweep3 inserts in O(n) per proxy (request it with --methods to run)";
    bullet("bullet-dbvt", "Bullet btDbvtBroadphase, defaults (Bullet's default broad phase)",
           BulletKind::Dbvt, true, 0, "");
    bullet("bullet-dbvt-deferred", "Bullet btDbvtBroadphase, m_deferedcollide = true",
           BulletKind::DbvtDeferred, true, 0, "");
    bullet("bullet-sap", "Bullet btAxisSweep3 (bt32BitAxisSweep3 from 16k), no raycast accelerator",
           BulletKind::AxisSweep, true, 50000, sweep_skip);
    bullet("bullet-sap-raycast", "Bullet btAxisSweep3 with its raycast accelerator (default)",
           BulletKind::AxisSweepRaycast, false, 50000, sweep_skip);
    appendBulletGrid(methods, sweep_skip);
#endif
#ifdef CDLAB_HAVE_FCL
    auto fcl = [&](std::string name, std::string description, FclManager manager, FclUpdate update,
                   bool in_default) {
        BenchMethodEntry m;
        m.name = std::move(name);
        m.description = std::move(description);
        m.peer = true;
        m.default_set = in_default;
        m.create = [manager, update]() -> std::unique_ptr<BenchMethod> {
            return std::make_unique<FclMethod>(manager, update);
        };
        methods.push_back(std::move(m));
    };
    fcl("fcl-dtree-refit", "FCL DynamicAABBTreeCollisionManager, update() (refit all)",
        FclManager::Tree, FclUpdate::Refit, false);
    fcl("fcl-dtree-update", "FCL DynamicAABBTreeCollisionManager, update(all objects)",
        FclManager::Tree, FclUpdate::Update, true);
    fcl("fcl-dtree-update-each", "FCL DynamicAABBTreeCollisionManager, update(obj) per object",
        FclManager::Tree, FclUpdate::UpdateEach, false);
    fcl("fcl-dtree-reinsert", "FCL DynamicAABBTreeCollisionManager, unregister + register",
        FclManager::Tree, FclUpdate::Reinsert, false);
    fcl("fcl-dtree-rebuild", "FCL DynamicAABBTreeCollisionManager, clear + registerObjects",
        FclManager::Tree, FclUpdate::Rebuild, false);
    fcl("fcl-sap-update", "FCL SaPCollisionManager, update(all objects)", FclManager::SweepAndPrune,
        FclUpdate::Update, false);
    fcl("fcl-sap-rebuild", "FCL SaPCollisionManager, clear + registerObjects",
        FclManager::SweepAndPrune, FclUpdate::Rebuild, true);
    appendFclGrid(methods);
#endif
}

}  // namespace app

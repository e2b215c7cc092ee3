// engine/src/contact_solver.cpp -- sequential impulses (Catto, "Fast and Simple Physics using
// Sequential Impulses", GDC 2006; "Iterative Dynamics with Temporal Coherence", GDC 2005;
// Mirtich & Canny 1995 for the impulse model) with accumulated-impulse clamping, warm starting,
// Coulomb friction on two tangent directions clamped by mu * normal impulse, restitution above a
// velocity threshold, and split-impulse position correction (pseudo velocities, Catto 2006 /
// Bullet's split impulse) so that pushing bodies apart never adds kinetic energy.
// Invariant: pairs arrive sorted and manifold points keep contact()'s order, and every loop runs
// in that order a fixed number of times: the result is deterministic.
#include "contact_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "collision/narrowphase/narrow_phase.h"

namespace engine {

namespace {

// Matching distance for warm starting, relative to the smaller bounding radius of the pair.
constexpr Real kMatchFraction = Real(0.1);
// Shock-propagation passes after the iterations (velocity, then position). With the lower body
// held fixed each contact converges in a few passes; measured on a 1 kg box under 1000 kg (and
// a 1-1000-1-1000 tower): 1 pass leaves a 2 cm creep over 10 s, 10 passes 0.15 mm, 20 none
// visible at 0.1 mm. Cost: the passes visit only contacts between levels, but in a resting
// pile that is nearly all of them, so they add up to 20/30 to the velocity work and 4x the
// position work (5 iterations) of the solver.
constexpr int kShockPasses = 20;

Real boundingRadius(const Body& b) {
    return b.local_bounds.sphere.center.norm() + b.local_bounds.sphere.radius;
}

// Two unit tangents completing n (Erin Catto's b2 / Jolt's GetNormalizedPerpendicular idea).
void tangents(const Vec3& n, Vec3& t1, Vec3& t2) {
    const Vec3 axis = std::abs(n.x()) < Real(0.57735) ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
    t1 = n.cross(axis).normalized();
    t2 = n.cross(t1);
}

Real effectiveMass(const Body& a, const Body& b, const Mat3& ia, const Mat3& ib, const Vec3& ra,
                   const Vec3& rb, const Vec3& d) {
    const Real k = a.inv_mass + b.inv_mass + d.dot((ia * ra.cross(d)).cross(ra)) +
                   d.dot((ib * rb.cross(d)).cross(rb));
    return k > 0 ? 1 / k : 0;
}

// Box-box face manifold by clipping (RTCD 5.x; Gottschalk's reference/incident faces, as in
// Box2D's b2CollidePolygons): the incident face of B (most anti-parallel to n) clipped by the
// side planes of A's reference face (most parallel to n), points kept within `margin` of it,
// reduced to at most 4 (deepest first, then the farthest from those kept). Used when contact()
// reports fewer than 3 points for two boxes whose normal is within kFaceCos of a face normal of
// A: nearly aligned boxes make an edge axis tie with the face axis, and one point cannot hold a
// box at rest. Points: point_a on the reference face, point_b on the incident face.
constexpr Real kFaceCos = Real(0.9995);  // about 1.8 degrees

int boxFaceManifold(const Body& a, const Pose& pa, const Body& b, const Pose& pb, const Vec3& n,
                    Real margin, std::array<collision::ManifoldPoint, 4>& out) {
    const Mat3 ra = pa.rotation();
    const Mat3 rb = pb.rotation();
    const Vec3& ha = a.shape.half_extents;
    const Vec3& hb = b.shape.half_extents;
    int k = 0;
    for (int i = 1; i < 3; ++i) {
        if (std::abs(ra.col(i).dot(n)) > std::abs(ra.col(k).dot(n))) k = i;
    }
    if (std::abs(ra.col(k).dot(n)) < kFaceCos) return 0;
    const Vec3 nf = ra.col(k).dot(n) >= 0 ? Vec3(ra.col(k)) : Vec3(-ra.col(k));
    const Vec3 ca = pa.position + nf * ha[k];
    const int iu = (k + 1) % 3, iv = (k + 2) % 3;
    const Vec3 u = ra.col(iu), v = ra.col(iv);
    int j = 0;
    for (int i = 1; i < 3; ++i) {
        if (std::abs(rb.col(i).dot(n)) > std::abs(rb.col(j).dot(n))) j = i;
    }
    const Vec3 m = rb.col(j).dot(n) >= 0 ? Vec3(-rb.col(j)) : Vec3(rb.col(j));
    const Vec3 cb = pb.position + m * hb[j];
    const int ju = (j + 1) % 3, jv = (j + 2) % 3;
    const Vec3 bu = rb.col(ju) * hb[ju], bv = rb.col(jv) * hb[jv];
    std::array<Vec3, 8> poly{cb - bu - bv, cb + bu - bv, cb + bu + bv, cb - bu + bv};
    int count = 4;
    // Sutherland-Hodgman against |(p - ca).u| <= ha[iu] and |(p - ca).v| <= ha[iv].
    const std::array<std::pair<Vec3, Real>, 4> planes{
        std::pair{u, ha[iu]}, std::pair{Vec3(-u), ha[iu]}, std::pair{v, ha[iv]},
        std::pair{Vec3(-v), ha[iv]}};
    for (const auto& [dir, h] : planes) {
        std::array<Vec3, 8> next;
        int next_count = 0;
        for (int i = 0; i < count && next_count < 8; ++i) {
            const Vec3& p0 = poly[static_cast<std::size_t>(i)];
            const Vec3& p1 = poly[static_cast<std::size_t>((i + 1) % count)];
            const Real d0 = (p0 - ca).dot(dir) - h;
            const Real d1 = (p1 - ca).dot(dir) - h;
            if (d0 <= 0) next[static_cast<std::size_t>(next_count++)] = p0;
            if ((d0 < 0 && d1 > 0) || (d0 > 0 && d1 < 0)) {
                if (next_count < 8) {
                    next[static_cast<std::size_t>(next_count++)] =
                        p0 + (p1 - p0) * (d0 / (d0 - d1));
                }
            }
        }
        poly = next;
        count = next_count;
        if (count == 0) return 0;
    }
    // Depth of each clipped point below the reference face; keep those within the margin.
    std::array<Real, 8> depth{};
    std::array<bool, 8> used{};
    int candidates = 0;
    for (int i = 0; i < count; ++i) {
        depth[static_cast<std::size_t>(i)] = (ca - poly[static_cast<std::size_t>(i)]).dot(nf);
        used[static_cast<std::size_t>(i)] = !(depth[static_cast<std::size_t>(i)] >= -margin);
        candidates += used[static_cast<std::size_t>(i)] ? 0 : 1;
    }
    int kept = 0;
    while (kept < 4 && kept < candidates) {
        int best = -1;
        Real score = -1;
        for (int i = 0; i < count; ++i) {
            if (used[static_cast<std::size_t>(i)]) continue;
            Real sc = 0;
            if (kept == 0) {
                sc = depth[static_cast<std::size_t>(i)] + 1e6 * margin;  // deepest first
            } else {
                sc = std::numeric_limits<Real>::max();
                for (int q = 0; q < kept; ++q) {
                    sc = std::min(sc, (poly[static_cast<std::size_t>(i)] -
                                       out[static_cast<std::size_t>(q)].point_b)
                                          .squaredNorm());
                }
            }
            if (sc > score) {
                score = sc;
                best = i;
            }
        }
        const std::size_t bi = static_cast<std::size_t>(best);
        used[bi] = true;
        collision::ManifoldPoint& mp = out[static_cast<std::size_t>(kept++)];
        mp.point_b = poly[bi];
        mp.point_a = poly[bi] + depth[bi] * nf;
        mp.depth = depth[bi];
    }
    return kept;
}

// Shock propagation order (Guendelman, Bridson, Fedkiw 2003 §5): each body's level by
// breadth-first search of the contact graph from the static bodies (level 0), and the points
// between two levels, in order of their lower level (then their own order).
template <class Point>
void shockOrder(const SolverBodies& bodies, const std::vector<Point>& points,
                std::vector<int>& level, std::vector<std::size_t>& shock_order) {
    constexpr int kUnreached = std::numeric_limits<int>::max();
    const std::size_t n = bodies.size();
    level.assign(n, kUnreached);
    std::vector<BodyId> frontier;
    for (std::size_t i = 0; i < n; ++i) {
        if (bodies[i].is_static) {
            level[i] = 0;
            frontier.push_back(static_cast<BodyId>(i));
        }
    }
    // Breadth-first search over the contact graph (adjacency in compressed rows, built
    // once: O(points + bodies)).
    std::vector<std::uint32_t> first(n + 1, 0);
    for (const Point& p : points) {
        ++first[p.a + 1];
        ++first[p.b + 1];
    }
    for (std::size_t i = 0; i < n; ++i) first[i + 1] += first[i];
    std::vector<BodyId> neighbour(first[n]);
    {
        std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
        for (const Point& p : points) {
            neighbour[fill[p.a]++] = p.b;
            neighbour[fill[p.b]++] = p.a;
        }
    }
    for (std::size_t head = 0; head < frontier.size(); ++head) {
        const BodyId u = frontier[head];
        for (std::uint32_t k = first[u]; k < first[u + 1]; ++k) {
            const BodyId v = neighbour[k];
            if (level[v] == kUnreached) {
                level[v] = level[u] + 1;
                frontier.push_back(v);
            }
        }
    }
    for (std::size_t k = 0; k < points.size(); ++k) {
        const Point& p = points[k];
        if (level[p.a] != level[p.b] && std::min(level[p.a], level[p.b]) != kUnreached) {
            shock_order.push_back(k);
        }
    }
    std::stable_sort(shock_order.begin(), shock_order.end(), [&](std::size_t x, std::size_t y) {
        return std::min(level[points[x].a], level[points[x].b]) <
               std::min(level[points[y].a], level[points[y].b]);
    });
}

// The upper body's share of a contact: effective mass along d with the lower body held fixed
// (a_up: the upper body is p.a).
template <class Point>
Real upperEffectiveMass(const SolverBodies& bodies, const std::vector<Mat3>& inv_inertia,
                        const Point& p, bool a_up, const Vec3& d) {
    const Body& up = bodies[a_up ? p.a : p.b];
    const Vec3& r = a_up ? p.ra : p.rb;
    const Real k = up.inv_mass + d.dot((inv_inertia[a_up ? p.a : p.b] * r.cross(d)).cross(r));
    return k > 0 ? 1 / k : Real(0);
}

// An impulse along a -> b applied to the upper body's velocities (v, w) alone.
template <class Point>
void applyToUpper(const SolverBodies& bodies, const std::vector<Mat3>& inv_inertia,
                  const Point& p, bool a_up, const Vec3& impulse, Vec3& v, Vec3& w) {
    const BodyId id = a_up ? p.a : p.b;
    const Vec3& r = a_up ? p.ra : p.rb;
    const Real sign = a_up ? -1 : 1;
    v += sign * impulse * bodies[id].inv_mass;
    w += sign * (inv_inertia[id] * r.cross(impulse));
}

// kShockPasses passes over the contacts between levels, in shock order; `solve(p, a_up, up)`
// updates one with its upper body `up` (a_up: it is p.a). The upper body is never static:
// static bodies are level 0, below every other.
template <class Point, class Solve>
void shockPasses(std::vector<Point>& points, const std::vector<std::size_t>& shock_order,
                 const std::vector<int>& level, const Solve& solve) {
    for (int pass = 0; pass < kShockPasses; ++pass) {
        for (const std::size_t k : shock_order) {
            Point& p = points[k];
            const bool a_up = level[p.a] > level[p.b];
            solve(p, a_up, a_up ? p.a : p.b);
        }
    }
}

// Speculative manifold (Catto, GDC 2013 "Continuous collision"): `query(pose_b)` (contact of a
// with b at pose_b) at b's pose, then, unless the pair is farther apart than `margin` or the
// query failed, again with b pushed `shift` = max(gap, 0) + margin deeper along the normal, so
// that corners within the margin of touching are in the manifold `c` (the caller moves them
// back: a negative depth is their gap) and a resting box keeps all four contacts from step to
// step. A point with a gap may approach by at most the gap in the step. False: no points.
template <class Query>
bool speculativeContact(const Query& query, const Pose& pose_b, Real margin,
                        collision::ContactOutput& c, Pose& moved, Real& shift) {
    const collision::ContactOutput c0 = query(pose_b);
    if (c0.state == collision::ContactState::Failed) return false;
    if (c0.state == collision::ContactState::Separated && !(c0.signed_distance < margin)) {
        return false;
    }
    shift = std::max(c0.signed_distance, Real(0)) + margin;
    moved = pose_b;
    moved.position -= shift * c0.normal;
    c = query(moved);
    return collision::isColliding(c.state) && c.manifold_size > 0;
}

}  // namespace

Body ContactSolver::makeWallBody() {
    Body wall;
    setStatic(wall);
    return wall;
}

void ContactSolver::addPairPoints(const SolverBodies& bodies, const collision::ProxyPair& pair,
                                  const std::vector<Mat3>& inv_inertia,
                                  const std::vector<Velocities>& vel, Real dt,
                                  const ContactSolverSettings& settings) {
    const Body& a = bodies[pair.a];
    const Body& b = bodies[pair.b];
    if (a.is_static && b.is_static) return;
    const Real size = std::min(boundingRadius(a), boundingRadius(b));
    const Real margin = settings.margin_fraction * size;
    collision::ContactOutput c;
    Pose moved;
    Real shift = 0;
    const auto query = [&](const Pose& pose_b) {
        return collision::contact(a.shape, a.pose(), b.shape, pose_b);
    };
    if (!speculativeContact(query, b.pose(), margin, c, moved, shift)) return;
    if (c.manifold_size < 3 && a.shape.type == collision::ShapeType::Box &&
        b.shape.type == collision::ShapeType::Box) {
        std::array<collision::ManifoldPoint, 4> face{};
        const int found = boxFaceManifold(a, a.pose(), b, moved, c.normal, margin, face);
        if (found > c.manifold_size) {
            c.manifold = face;
            c.manifold_size = found;
        }
    }
    addManifoldPoints(bodies, pair.a, pair.b, c, shift, size, std::max(a.restitution, b.restitution),
                      std::sqrt(a.friction * b.friction), inv_inertia, vel, dt, settings);
}

void ContactSolver::addWallPoints(const SolverBodies& bodies, const Wall& wall, BodyId wall_id,
                                  BodyId body, const std::vector<Mat3>& inv_inertia,
                                  const std::vector<Velocities>& vel, Real dt,
                                  const ContactSolverSettings& settings) {
    // The body against the wall's half-space (collision/narrowphase/half_space.h), with the
    // speculative margin of a body pair whose other body is as large as this one.
    const Body& b = bodies[body];
    if (b.is_static) return;
    const Real size = boundingRadius(b);
    const Real margin = settings.margin_fraction * size;
    collision::ContactOutput c;
    Pose moved;
    Real shift = 0;
    const auto query = [&](const Pose& pose_b) {
        return collision::contact(wall.plane, b.shape, pose_b);
    };
    if (!speculativeContact(query, b.pose(), margin, c, moved, shift)) return;
    addManifoldPoints(bodies, wall_id, body, c, shift, size,
                      std::max(wall.restitution, b.restitution),
                      std::sqrt(wall.friction * b.friction), inv_inertia, vel, dt, settings);
}

void ContactSolver::addManifoldPoints(const SolverBodies& bodies, BodyId a_id, BodyId b_id,
                                      collision::ContactOutput& c, Real shift, Real size,
                                      Real restitution, Real friction,
                                      const std::vector<Mat3>& inv_inertia,
                                      const std::vector<Velocities>& vel, Real dt,
                                      const ContactSolverSettings& settings) {
    const Body& a = bodies[a_id];
    const Body& b = bodies[b_id];
    for (int k = 0; k < c.manifold_size; ++k) {
        collision::ManifoldPoint& m = c.manifold[static_cast<std::size_t>(k)];
        m.point_b += shift * c.normal;
        m.depth -= shift;  // < 0: a gap
    }
    // Previous points of this pair (previous_ is sorted by (a, b)).
    Point key;
    key.a = a_id;
    key.b = b_id;
    const auto range = std::equal_range(
        previous_.begin(), previous_.end(), key,
        [](const Point& x, const Point& y) { return x.a < y.a || (x.a == y.a && x.b < y.b); });
    const std::span<const Point> previous(range.first, range.second);
    for (int k = 0; k < c.manifold_size; ++k) {
        const collision::ManifoldPoint& m = c.manifold[static_cast<std::size_t>(k)];
        Point p;
        p.a = a_id;
        p.b = b_id;
        const Vec3 at = (m.point_a + m.point_b) / 2;
        p.ra = at - a.position;
        p.rb = at - b.position;
        p.normal = c.normal;
        tangents(p.normal, p.t1, p.t2);
        const Mat3& ia = inv_inertia[a_id];
        const Mat3& ib = inv_inertia[b_id];
        p.mass_n = effectiveMass(a, b, ia, ib, p.ra, p.rb, p.normal);
        p.mass_t1 = effectiveMass(a, b, ia, ib, p.ra, p.rb, p.t1);
        p.mass_t2 = effectiveMass(a, b, ia, ib, p.ra, p.rb, p.t2);
        p.friction = friction;
        p.depth = m.depth;
        p.slop = settings.slop_fraction * size;
        p.local_a = a.pose().applyInverse(at);
        p.feature_a = c.feature_a;
        p.feature_b = c.feature_b;
        const Vec3 dv = (vel[b_id].v + vel[b_id].w.cross(p.rb)) -
                        (vel[a_id].v + vel[a_id].w.cross(p.ra));
        const Real vn = dv.dot(p.normal);
        const bool bounce = vn < -settings.restitution_threshold;
        if (m.depth < 0 && !(bounce && -vn * dt > -m.depth)) {
            // Speculative, not closing the gap in this step: approach by at most the gap.
            p.velocity_bias = m.depth / dt;
        } else {
            // Touching, or a speculative point that closes its gap within the step: bounce
            // now (the pair turns back at most the gap early, less than the margin).
            p.velocity_bias = bounce ? -restitution * vn : 0;
        }
        warmStart(p, size, previous);
        points_.push_back(p);
    }
}

void ContactSolver::warmStart(Point& p, Real size, std::span<const Point> range) {
    Real best = kMatchFraction * size;
    for (const Point& q : range) {
        if (q.feature_a.type != p.feature_a.type || q.feature_a.index != p.feature_a.index ||
            q.feature_b.type != p.feature_b.type || q.feature_b.index != p.feature_b.index) {
            continue;
        }
        const Real d = (q.local_a - p.local_a).norm();
        if (d < best) {
            best = d;
            p.impulse_n = q.impulse_n;
            // Tangent impulses carried over as a world vector onto the new basis.
            const Vec3 ft = q.impulse_t1 * q.t1 + q.impulse_t2 * q.t2;
            p.impulse_t1 = ft.dot(p.t1);
            p.impulse_t2 = ft.dot(p.t2);
        }
    }
}

void ContactSolver::solvePositions(const SolverBodies& bodies,
                                   const std::vector<Mat3>& inv_inertia,
                                   const std::vector<int>& level,
                                   const std::vector<std::size_t>& shock_order, Real dt,
                                   const ContactSolverSettings& settings,
                                   std::vector<Vec3>& pseudo_linear,
                                   std::vector<Vec3>& pseudo_angular) {
    // Split impulse: pseudo velocities that remove baumgarte * (depth - slop) / dt of each
    // penetration, applied to the positions of this step only (never to the momenta).
    // One split-impulse update of point p: `mass` the effective mass along the normal,
    // `push(impulse)` applies a pseudo impulse along a -> b.
    auto solvePseudo = [&](Point& p, Real mass, const auto& push) {
        const Vec3 dv = (pseudo_linear[p.b] + pseudo_angular[p.b].cross(p.rb)) -
                        (pseudo_linear[p.a] + pseudo_angular[p.a].cross(p.ra));
        const Real target = settings.baumgarte * std::max(p.depth - p.slop, Real(0)) / dt;
        const Real old = p.pseudo_n;
        p.pseudo_n = std::max(old - mass * (dv.dot(p.normal) - target), Real(0));
        push((p.pseudo_n - old) * p.normal);
    };
    for (int it = 0; it < settings.position_iterations; ++it) {
        for (Point& p : points_) {
            solvePseudo(p, p.mass_n, [&](const Vec3& impulse) {
                const Body& a = bodies[p.a];
                const Body& b = bodies[p.b];
                if (!a.is_static) {
                    pseudo_linear[p.a] -= impulse * a.inv_mass;
                    pseudo_angular[p.a] -= inv_inertia[p.a] * p.ra.cross(impulse);
                }
                if (!b.is_static) {
                    pseudo_linear[p.b] += impulse * b.inv_mass;
                    pseudo_angular[p.b] += inv_inertia[p.b] * p.rb.cross(impulse);
                }
            });
        }
    }

    // The same shock passes for the split impulse: the lower body's pseudo velocity held fixed.
    shockPasses(points_, shock_order, level, [&](Point& p, bool a_up, BodyId up) {
        solvePseudo(p, upperEffectiveMass(bodies, inv_inertia, p, a_up, p.normal),
                    [&](const Vec3& impulse) {
                        applyToUpper(bodies, inv_inertia, p, a_up, impulse, pseudo_linear[up],
                                     pseudo_angular[up]);
                    });
    });
}

void ContactSolver::solve(std::span<Body> bodies, std::span<const collision::ProxyPair> pairs,
                          std::span<const Wall> walls,
                          std::span<const WallCandidate> wall_candidates, Real dt,
                          const ContactSolverSettings& settings,
                          std::vector<Vec3>& pseudo_linear, std::vector<Vec3>& pseudo_angular) {
    const std::size_t n = bodies.size();
    const SolverBodies table{bodies, &wall_body_, walls.size()};
    const std::size_t total = table.size();
    pseudo_linear.assign(total, Vec3::Zero());
    pseudo_angular.assign(total, Vec3::Zero());
    points_.clear();
    if (n != body_count_) previous_.clear();  // wall indices moved: nothing to warm-start
    body_count_ = n;

    // World inverse inertias at the present poses, once per body (zero for the walls).
    std::vector<Mat3> inv_inertia(total, Mat3::Zero());
    std::vector<Velocities> vel(total);
    for (std::size_t i = 0; i < n; ++i) {
        inv_inertia[i] = bodies[i].invInertiaWorld();
        vel[i].v = bodies[i].velocity();
        vel[i].w = inv_inertia[i] * bodies[i].angular_momentum;
    }

    for (const collision::ProxyPair& pair : pairs) {
        addPairPoints(table, pair, inv_inertia, vel, dt, settings);
    }
    // After every body pair, walls in order: points_ stays sorted by (a, b).
    for (const WallCandidate& w : wall_candidates) {
        addWallPoints(table, walls[w.wall], static_cast<BodyId>(n + w.wall), w.body, inv_inertia,
                      vel, dt, settings);
    }

    auto apply = [&](const Point& p, const Vec3& impulse) {
        const Body& a = table[p.a];
        const Body& b = table[p.b];
        if (!a.is_static) {
            vel[p.a].v -= impulse * a.inv_mass;
            vel[p.a].w -= inv_inertia[p.a] * p.ra.cross(impulse);
        }
        if (!b.is_static) {
            vel[p.b].v += impulse * b.inv_mass;
            vel[p.b].w += inv_inertia[p.b] * p.rb.cross(impulse);
        }
    };
    // Warm starting.
    for (const Point& p : points_) {
        apply(p, p.impulse_n * p.normal + p.impulse_t1 * p.t1 + p.impulse_t2 * p.t2);
    }
    auto relative = [&](const Point& p) -> Vec3 {
        return (vel[p.b].v + vel[p.b].w.cross(p.rb)) - (vel[p.a].v + vel[p.a].w.cross(p.ra));
    };
    // One update of point p, friction first (clamped by the present normal impulse), then the
    // normal: `mass(d, cached)` is the effective mass along d (`cached` the pair's own),
    // `push(impulse)` applies an impulse along a -> b.
    auto solvePoint = [&](Point& p, const auto& mass, const auto& push) {
        const Vec3 dv = relative(p);
        const Real max_f = p.friction * p.impulse_n;
        const Real old1 = p.impulse_t1;
        const Real old2 = p.impulse_t2;
        Real new1 = old1 - mass(p.t1, p.mass_t1) * dv.dot(p.t1);
        Real new2 = old2 - mass(p.t2, p.mass_t2) * dv.dot(p.t2);
        // Coulomb cone clamped as a disc (isotropic friction).
        const Real len = std::sqrt(new1 * new1 + new2 * new2);
        if (len > max_f && len > 0) {
            new1 *= max_f / len;
            new2 *= max_f / len;
        }
        p.impulse_t1 = new1;
        p.impulse_t2 = new2;
        push((new1 - old1) * p.t1 + (new2 - old2) * p.t2);

        const Real vn = relative(p).dot(p.normal);
        const Real old_n = p.impulse_n;
        p.impulse_n = std::max(old_n - mass(p.normal, p.mass_n) * (vn - p.velocity_bias), Real(0));
        push((p.impulse_n - old_n) * p.normal);
    };
    const auto cached_mass = [](const Vec3&, Real cached) { return cached; };
    for (int it = 0; it < settings.velocity_iterations; ++it) {
        for (Point& p : points_) {
            solvePoint(p, cached_mass, [&](const Vec3& impulse) { apply(p, impulse); });
        }
    }
    // Shock propagation (Guendelman, Bridson, Fedkiw 2003 §5): levels by breadth-first search
    // of the contact graph from the static bodies (0); contacts in order of their lower level
    // (then their order), each solved once more with its lower body held fixed, so corrections
    // travel up the stack and never back down. Contacts within one level, and bodies no static
    // body supports, are left as the iterations solved them.
    std::vector<std::size_t> shock_order;
    std::vector<int> level;
    if (settings.shock_propagation && !points_.empty()) {
        shockOrder(table, points_, level, shock_order);
    }
    auto upperMass = [&](const Point& p, bool a_up, const Vec3& d) {
        return upperEffectiveMass(table, inv_inertia, p, a_up, d);
    };
    auto applyUpper = [&](const Point& p, bool a_up, const Vec3& impulse, Vec3& v, Vec3& w) {
        applyToUpper(table, inv_inertia, p, a_up, impulse, v, w);
    };
    shockPasses(points_, shock_order, level, [&](Point& p, bool a_up, BodyId up) {
        solvePoint(
            p, [&](const Vec3& d, Real) { return upperMass(p, a_up, d); },
            [&](const Vec3& impulse) { applyUpper(p, a_up, impulse, vel[up].v, vel[up].w); });
    });

    for (std::size_t i = 0; i < n; ++i) {
        Body& b = bodies[i];
        if (b.is_static) continue;
        b.linear_momentum = b.mass * vel[i].v;
        // L = I_world w = R I R^T w.
        const Mat3 r = b.orientation.toRotationMatrix();
        b.angular_momentum = r * (b.inertia_body * (r.transpose() * vel[i].w));
    }

    solvePositions(table, inv_inertia, level, shock_order, dt, settings, pseudo_linear,
                   pseudo_angular);

    previous_ = points_;  // already sorted by (a, b): pairs were sorted
}

void ContactSolver::pushedPairs(std::vector<collision::ProxyPair>& out) const {
    out.clear();
    for (const Point& p : points_) {
        if (p.impulse_n > 0 && std::size_t(p.a) < body_count_ && std::size_t(p.b) < body_count_) {
            out.push_back({std::min(p.a, p.b), std::max(p.a, p.b)});
        }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace engine

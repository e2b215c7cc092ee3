// app/lab/bench/convex_reference.cpp -- the long-double ground truth of `cdlab bench convex`
// (convex_reference.h). Invariant: nothing here calls collision's queries; every answer comes from
// the poses' quaternions and the shapes' dimensions through closed forms or brute force, in long
// double (64-bit mantissa on x86-64), so its own rounding is ~1e-19 of the size, far below the
// double-precision errors it measures.
#include "convex_reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace app {
namespace {

using collision::Pose;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;
using LD = long double;
// The only long-double Eigen types: this file's arithmetic, never in an interface.
using V = Eigen::Matrix<LD, 3, 1>;
using M = Eigen::Matrix<LD, 3, 3>;

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

struct Frame {
    M rot;     ///< local axes as columns, world frame
    V centre;  ///< world
};

Frame frameOf(const Pose& pose) {
    const Eigen::Quaternion<LD> q(
        static_cast<LD>(pose.orientation.w()), static_cast<LD>(pose.orientation.x()),
        static_cast<LD>(pose.orientation.y()), static_cast<LD>(pose.orientation.z()));
    return {q.normalized().toRotationMatrix(), pose.position.cast<LD>()};
}

enum class Kind { Sphere, Capsule, Box, Other };

// A box given as the bench's 8-point hull (vertex 7 is +half_extents) counts as the box.
Kind kindOf(const Shape& s, V& half) {
    switch (s.type) {
        case ShapeType::Sphere:
            return Kind::Sphere;
        case ShapeType::Capsule:
            return Kind::Capsule;
        case ShapeType::Box:
            half = s.half_extents.cast<LD>();
            return Kind::Box;
        case ShapeType::ConvexHull:
            if (s.hull && s.hull->vertices.size() == 8) {
                half = s.hull->vertices.back().cwiseAbs().cast<LD>();
                return Kind::Box;
            }
            return Kind::Other;
        default:
            return Kind::Other;
    }
}

struct Segment {
    V p;
    V q;
};

// A sphere's core is its centre, a capsule's its axis segment.
Segment coreOf(const Shape& s, const Frame& f) {
    if (s.type == ShapeType::Sphere) return {f.centre, f.centre};
    const V half = f.rot.col(1) * static_cast<LD>(s.half_height);
    return {f.centre - half, f.centre + half};
}

LD pointSegment(const V& x, const Segment& s) {
    const V d = s.q - s.p;
    const LD len2 = d.squaredNorm();
    const LD t = len2 > 0 ? std::clamp((x - s.p).dot(d) / len2, LD(0), LD(1)) : LD(0);
    return (x - (s.p + t * d)).norm();
}

// The closest pair of two segments is an end point against the other segment, or an interior
// pair where both lines' closest parameters lie inside (RTCD 5.1.8).
LD segmentSegment(const Segment& a, const Segment& b) {
    LD best = std::min({pointSegment(a.p, b), pointSegment(a.q, b), pointSegment(b.p, a),
                        pointSegment(b.q, a)});
    const V d1 = a.q - a.p;
    const V d2 = b.q - b.p;
    const V r = a.p - b.p;
    const LD aa = d1.squaredNorm();
    const LD ee = d2.squaredNorm();
    const LD bb = d1.dot(d2);
    const LD c = d1.dot(r);
    const LD f = d2.dot(r);
    const LD denom = aa * ee - bb * bb;
    if (aa > 0 && ee > 0 && denom > 0) {
        const LD s = (bb * f - c * ee) / denom;
        const LD t = (aa * f - bb * c) / denom;
        if (s > 0 && s < 1 && t > 0 && t < 1) {
            best = std::min(best, ((a.p + s * d1) - (b.p + t * d2)).norm());
        }
    }
    return best;
}

// Signed distance of world point x from the box (half extents h, frame f); negative inside.
LD pointBox(const V& x, const V& h, const Frame& f) {
    const V q = (f.rot.transpose() * (x - f.centre)).cwiseAbs() - h;
    return q.cwiseMax(LD(0)).norm() + std::min(q.maxCoeff(), LD(0));
}

// Support function max over the shape of u.x (u world, any length).
LD support(const Shape& s, Kind kind, const V& half, const Frame& f, const V& u) {
    const V local = f.rot.transpose() * u;
    LD h = u.dot(f.centre);
    switch (kind) {
        case Kind::Sphere:
            return h + static_cast<LD>(s.radius) * u.norm();
        case Kind::Capsule:
            return h + std::abs(local.y()) * static_cast<LD>(s.half_height) +
                   static_cast<LD>(s.radius) * u.norm();
        case Kind::Box:
            return h + local.cwiseAbs().dot(half);
        case Kind::Other:
            break;
    }
    return std::numeric_limits<LD>::quiet_NaN();
}

// Least overlap over the 15 axes (positive: every axis overlaps, and it is the depth).
LD boxSatDepth(const V& ha, const Frame& fa, const V& hb, const Frame& fb) {
    std::array<V, 15> axes;
    int n = 0;
    for (int i = 0; i < 3; ++i) axes[static_cast<std::size_t>(n++)] = fa.rot.col(i);
    for (int j = 0; j < 3; ++j) axes[static_cast<std::size_t>(n++)] = fb.rot.col(j);
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            const V c = fa.rot.col(i).cross(fb.rot.col(j));
            const LD len = c.norm();
            if (len > LD(1e-15)) axes[static_cast<std::size_t>(n++)] = c / len;  // parallel: faces cover it
        }
    }
    const V t = fb.centre - fa.centre;
    LD least = std::numeric_limits<LD>::infinity();
    for (int k = 0; k < n; ++k) {
        const V& u = axes[static_cast<std::size_t>(k)];
        const LD ra = (fa.rot.transpose() * u).cwiseAbs().dot(ha);
        const LD rb = (fb.rot.transpose() * u).cwiseAbs().dot(hb);
        least = std::min(least, ra + rb - std::abs(t.dot(u)));
    }
    return least;
}

std::array<V, 8> corners(const V& h, const Frame& f) {
    std::array<V, 8> c;
    for (int i = 0; i < 8; ++i) {
        const V local((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
        c[static_cast<std::size_t>(i)] = f.rot * local + f.centre;
    }
    return c;
}

// Apart boxes: the closest pair is a vertex against the other box or an edge against an edge.
LD boxBoxDistance(const V& ha, const Frame& fa, const V& hb, const Frame& fb) {
    const std::array<V, 8> ca = corners(ha, fa);
    const std::array<V, 8> cb = corners(hb, fb);
    LD best = std::numeric_limits<LD>::infinity();
    for (const V& x : ca) best = std::min(best, pointBox(x, hb, fb));
    for (const V& x : cb) best = std::min(best, pointBox(x, ha, fa));
    std::array<Segment, 12> ea;
    std::array<Segment, 12> eb;
    int n = 0;
    for (int i = 0; i < 8; ++i) {
        for (int k = 0; k < 3; ++k) {
            if (i & (1 << k)) continue;
            const auto j = static_cast<std::size_t>(i | (1 << k));
            ea[static_cast<std::size_t>(n)] = {ca[static_cast<std::size_t>(i)], ca[j]};
            eb[static_cast<std::size_t>(n)] = {cb[static_cast<std::size_t>(i)], cb[j]};
            ++n;
        }
    }
    for (const Segment& s : ea) {
        for (const Segment& t : eb) best = std::min(best, segmentSegment(s, t));
    }
    return best;
}

}  // namespace

Real exactSignedDistance(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    V ha;
    V hb;
    const Kind ka = kindOf(a, ha);
    const Kind kb = kindOf(b, hb);
    const Frame fa = frameOf(pose_a);
    const Frame fb = frameOf(pose_b);
    const bool round_a = ka == Kind::Sphere || ka == Kind::Capsule;
    const bool round_b = kb == Kind::Sphere || kb == Kind::Capsule;
    if (round_a && round_b) {
        return static_cast<Real>(segmentSegment(coreOf(a, fa), coreOf(b, fb)) -
                                 static_cast<LD>(a.radius) - static_cast<LD>(b.radius));
    }
    if (ka == Kind::Sphere && kb == Kind::Box) {
        return static_cast<Real>(pointBox(fa.centre, hb, fb) - static_cast<LD>(a.radius));
    }
    if (ka == Kind::Box && kb == Kind::Sphere) {
        return static_cast<Real>(pointBox(fb.centre, ha, fa) - static_cast<LD>(b.radius));
    }
    if (ka == Kind::Box && kb == Kind::Box) {
        const LD depth = boxSatDepth(ha, fa, hb, fb);
        return static_cast<Real>(depth > 0 ? -depth : boxBoxDistance(ha, fa, hb, fb));
    }
    return kNaN;
}

Real exactOverlapAlong(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                       const Vec3& n) {
    V ha;
    V hb;
    const Kind ka = kindOf(a, ha);
    const Kind kb = kindOf(b, hb);
    const V u = n.cast<LD>().normalized();
    return static_cast<Real>(support(a, ka, ha, frameOf(pose_a), u) +
                             support(b, kb, hb, frameOf(pose_b), -u));
}

Real surfaceDistance(const Shape& s, const Pose& pose, const Vec3& p) {
    V h;
    const Kind kind = kindOf(s, h);
    const Frame f = frameOf(pose);
    const V x = p.cast<LD>();
    switch (kind) {
        case Kind::Sphere:
        case Kind::Capsule:
            return static_cast<Real>(pointSegment(x, coreOf(s, f)) - static_cast<LD>(s.radius));
        case Kind::Box:
            return static_cast<Real>(pointBox(x, h, f));
        case Kind::Other:
            break;
    }
    return kNaN;
}

}  // namespace app

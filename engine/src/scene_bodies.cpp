// engine/src/scene_bodies.cpp -- the scene's `bodies`: shapes (hull and mesh geometry imported
// once per (file, scale, shape) and shared), poses, motion, mass, and `repeat` populations.
// Conventions: `position` is the body's centre of mass (hull and mesh vertices are re-centred
// on it); `euler_deg: [x, y, z]` is intrinsic X, then Y, then Z, i.e. R = Rx(x) Ry(y) Rz(z);
// `angular_velocity` is in the world frame.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include "collision/broadphase/broad_phase.h"
#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "engine/mass_properties.h"
#include "engine/mesh_import.h"
#include "repeat_placement.h"
#include "scene_parser.h"

namespace engine::scene_parsing {

// A point set without a convex hull (flat, on a line, one point) is the file's shape, not a
// failure of the hull: say so, and what to use instead.
void SceneParser::failFlatMesh(ShapeType type, const std::string& hull_error,
                               const collision::TriangleMesh& mesh, const fs::path& resolved,
                               const Entry& file_entry, const std::string& path) const {
    const std::size_t n = mesh.vertices.size();
    const std::string counts = std::to_string(n) + (n == 1 ? " vertex" : " vertices") + ", " +
                               std::to_string(mesh.triangles.size()) + " triangle" +
                               (mesh.triangles.size() == 1 ? "" : "s");
    std::string flat;
    if (hull_error == "points are coplanar" || n == 3) {
        flat = "lie in one plane";
    } else if (hull_error == "points are collinear" || n == 2) {
        flat = "lie on one line";
    } else if (hull_error == "all points coincide" || n < 2) {
        flat = "coincide";
    }
    if (flat.empty()) {
        fail(file_entry.key_node, path,
             "cannot build the convex hull of '" + resolved.string() + "': " + hull_error);
    }
    std::string what = "'" + resolved.string() + "' has no volume: its points " + flat + " (" +
                       counts + "); ";
    if (type == ShapeType::ConvexHull) {
        what += "a body is a solid, so its hull needs points in three dimensions";
    } else {
        // Contact response, CCD against convex bodies and the bounding volumes all use a mesh's
        // convex hull (collision/geometry/shape.h), which flat points do not have.
        what +=
            "a mesh body needs its convex hull (contact response, bounds), which flat points "
            "do not have: give the surface a thickness, or use 'shape: box' with a zero half "
            "extent and 'mass' for a flat plate";
    }
    fail(file_entry.key_node, path, what);
}

const PreparedShape& SceneParser::prepareMeshShape(ShapeType type, const std::string& file,
                                                   Real scale, const Entry& file_entry,
                                                   const std::string& path,
                                                   const std::string& bvh_name) {
    fs::path resolved = fs::path(file);
    if (resolved.is_relative()) resolved = base_dir_ / resolved;
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(resolved, ec);
    if (ec) canonical = resolved.lexically_normal();
    const auto key = std::make_tuple(canonical.string(), scale, static_cast<int>(type));
    if (const auto it = mesh_cache_.find(key); it != mesh_cache_.end()) return it->second;

    // Errors about the file are reported at the `file:` key. One import per file, at scale 1,
    // shared by every hull and mesh body made from it: assimp is the slow part (under ASan one OBJ
    // import costs about half a second, so a scene with many scales of one file took seconds).
    auto import_it = import_cache_.find(canonical.string());
    if (import_it == import_cache_.end()) {
        import_it = import_cache_
                        .emplace(canonical.string(),
                                 std::make_shared<const MeshImportOutput>(importMesh(resolved, 1)))
                        .first;
        // What the import changed (triangles dropped, vertices merged by float rounding): said
        // once per file, at the first body that uses it.
        const std::string changes = describeImportChanges(import_it->second->report);
        if (import_it->second->ok && !changes.empty()) {
            notes_.push_back(formatMessage(file_, file_entry.key_node.Mark(), path,
                                           "'" + file + "': " + changes));
        }
    }
    // Scaling after the import gives importMesh(file, scale)'s mesh unless rounding at an extreme
    // scale made a kept triangle degenerate (vertices merge, or the area vanishes) or the file
    // only works at its scale (a failed import); then that scale is imported on its own, so the
    // welding and degenerate-triangle rules and the error messages are importMesh's exactly.
    MeshImportOutput imported = *import_it->second;
    bool exact = imported.ok;
    for (Vec3& v : imported.mesh.vertices) {
        v *= scale;
        exact = exact && v.allFinite();
    }
    for (const auto& t : imported.mesh.triangles) {
        if (!exact) break;
        const Vec3& a = imported.mesh.vertices[t[0]];
        const Vec3& b = imported.mesh.vertices[t[1]];
        const Vec3& c = imported.mesh.vertices[t[2]];
        exact = a != b && b != c && a != c && (b - a).cross(c - a).squaredNorm() > 0;
    }
    if (!exact) {
        imported = importMesh(resolved, scale);
        if (!imported.ok) fail(file_entry.key_node, path, imported.error);
    }
    const collision::ConvexHullOutput hull = collision::computeConvexHull(imported.mesh.vertices);
    if (!hull.ok) failFlatMesh(type, hull.error, imported.mesh, resolved, file_entry, path);
    // Mass properties of the solid the body is: the hull; a closed mesh's own volume; an open
    // mesh's hull (a surface bounds no volume: its hull is the solid it most plausibly stands
    // for, and is always closed). Then the geometry moves so that the local origin is the centre
    // of mass.
    PreparedShape prepared;
    const Shape hull_shape =
        Shape::convexHull(std::make_shared<const collision::ConvexPolytope>(hull.hull));
    MassPropertiesOutput mp;
    if (type == ShapeType::Mesh) {
        prepared.boundary_edges = boundaryEdgeCount(imported.mesh.triangles);
        if (prepared.boundary_edges == 0) {
            mp = computeMassProperties(
                Shape::triangleMesh(std::make_shared<const collision::TriangleMesh>(imported.mesh),
                                    std::make_shared<const collision::ConvexPolytope>(hull.hull),
                                    nullptr),  // only for the mass properties: no hierarchy
                1);
            if (!mp.ok) prepared.volume_error = mp.error;
        }
    }
    if (!mp.ok) mp = computeMassProperties(hull_shape, 1);
    if (!mp.ok) fail(file_entry.key_node, path, "'" + resolved.string() + "': " + mp.error);
    const Vec3 com = mp.props.center_of_mass;
    collision::ConvexPolytope centred_hull = hull.hull;
    for (Vec3& v : centred_hull.vertices) v -= com;
    prepared.unit = mp.props;
    if (type == ShapeType::ConvexHull) {
        prepared.shape = Shape::convexHull(
            std::make_shared<const collision::ConvexPolytope>(std::move(centred_hull)));
    } else {
        collision::TriangleMesh centred_mesh = imported.mesh;
        for (Vec3& v : centred_mesh.vertices) v -= com;
        // The hierarchy is built once here, in the body frame, and shared by every body made
        // from this file (rigid motion needs no rebuild).
        auto mesh = std::make_shared<const collision::TriangleMesh>(std::move(centred_mesh));
        std::shared_ptr<const collision::MeshBvh> bvh = collision::buildMeshBvh(bvh_name, *mesh);
        prepared.shape = Shape::triangleMesh(
            std::move(mesh),
            std::make_shared<const collision::ConvexPolytope>(std::move(centred_hull)),
            std::move(bvh));
    }
    return mesh_cache_.emplace(key, std::move(prepared)).first->second;
}

// The shape a `bodies` entry names, and the keys that apply to it; a key of another shape, or
// both keys of an exclusive pair, is an error at that key.
ShapeType SceneParser::bodyShape(const std::vector<Entry>& es, const YAML::Node& n,
                                 const std::string& path, std::string& shape_name,
                                 std::vector<std::string_view>& shape_keys) const {
    const Entry& shape_entry = require(es, "shape", n, path);
    shape_name = readString(shape_entry.value, childPath(path, "shape"));
    ShapeType type = ShapeType::Sphere;
    if (shape_name == "sphere") {
        type = ShapeType::Sphere;
        shape_keys = {"radius"};
    } else if (shape_name == "box") {
        type = ShapeType::Box;
        shape_keys = {"half_extents"};
    } else if (shape_name == "capsule") {
        type = ShapeType::Capsule;
        shape_keys = {"radius", "half_height"};
    } else if (shape_name == "hull" || shape_name == "mesh") {
        type = shape_name == "hull" ? ShapeType::ConvexHull : ShapeType::Mesh;
        shape_keys = {"file", "scale"};
    } else {
        fail(shape_entry.value, childPath(path, "shape"),
             "unknown shape '" + shape_name +
                 "' (expected one of: " + join({"sphere", "box", "capsule", "hull", "mesh"}) + ")");
    }
    constexpr std::string_view kShapeSpecific[] = {"radius", "half_height", "half_extents", "file",
                                                   "scale"};
    for (const Entry& e : es) {
        for (const std::string_view k : kShapeSpecific) {
            if (e.key != k) continue;
            bool applies = false;
            for (const std::string_view s : shape_keys) applies = applies || s == k;
            if (!applies) {
                fail(e.key_node, childPath(path, e.key),
                     "does not apply to shape '" + shape_name + "'");
            }
        }
    }
    // Pairs that exclude each other: reported at whichever comes second in the file.
    constexpr std::pair<std::string_view, std::string_view> kExclusive[] = {
        {"mass", "density"}, {"orientation_wxyz", "euler_deg"}};
    for (const auto& [a, b] : kExclusive) {
        const Entry* ea = find(es, a);
        const Entry* eb = find(es, b);
        if (ea != nullptr && eb != nullptr) {
            const Entry* second = ea->key_node.Mark().pos > eb->key_node.Mark().pos ? ea : eb;
            fail(second->key_node, childPath(path, second->key),
                 "give either '" + std::string(a) + "' or '" + std::string(b) + "', not both");
        }
    }
    return type;
}

// Every value of a `bodies` entry, read and checked at its key, before the shape is built.
BodyValues SceneParser::readBodyValues(const std::vector<Entry>& es, const YAML::Node& n,
                                       const std::string& path, std::string default_name,
                                       const std::vector<std::string_view>& shape_keys,
                                       const Scene& scene, bool needs_position) const {
    BodyValues b;
    b.name = std::move(default_name);
    b.restitution = scene.world.restitution;
    b.friction = scene.world.friction;
    const Entry* repeat_entry = find(es, "repeat");
    if (repeat_entry != nullptr) {
        for (const Entry& e : es) {
            for (const std::string_view k : kGeneratedKeys) {
                if (e.key == k) {
                    fail(e.key_node, childPath(path, e.key),
                         "does not apply with 'repeat' (repeat generates it)");
                }
            }
        }
    } else if (needs_position) {
        require(es, "position", n, path);
    }
    for (const std::string_view k : shape_keys) {
        if (k != "scale") require(es, k, n, path);
    }
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        const YAML::Node& v = e.value;
        if (e.key == "name") {
            b.name = readString(v, p);
        } else if (e.key == "radius") {
            b.radius = readReal(v, p);
            if (!(b.radius > 0)) fail(v, p, "must be > 0");
        } else if (e.key == "half_height") {
            b.half_height = readReal(v, p);
            if (!(b.half_height >= 0)) fail(v, p, "must be >= 0");
        } else if (e.key == "half_extents") {
            b.half_extents = readVec3(v, p);
            for (int a = 0; a < 3; ++a) {
                if (!(b.half_extents[a] >= 0)) fail(v[a], indexPath(p, a), "must be >= 0");
            }
        } else if (e.key == "file") {
            readString(v, p);
            if (v.Scalar().empty()) fail(v, p, "must not be empty");
            b.file_entry = &e;
        } else if (e.key == "scale") {
            b.scale = readReal(v, p);
            if (!(b.scale > 0)) fail(v, p, "must be > 0");
            // The hull and mass properties multiply up to three coordinates: at 1e300 they
            // overflowed ("points are coplanar"), at 1e-300 underflowed ("no triangles").
            if (!(b.scale >= kMinMeshScale && b.scale <= kMaxMeshScale)) {
                fail(v, p,
                     "must be in [" + formatLimit(kMinMeshScale) + ", " +
                         formatLimit(kMaxMeshScale) +
                         "]: beyond, products of the scaled coordinates over- or underflow");
            }
        } else if (e.key == "position") {
            b.position = readVec3(v, p);
            if (!scene.world.bounds.contains(b.position)) {
                fail(v, p, "is outside the world bounds");
            }
        } else if (e.key == "orientation_wxyz") {
            if (!v.IsSequence() || v.size() != 4) fail(v, p, "expected a list of 4 numbers");
            Real q[4];
            for (std::size_t i = 0; i < 4; ++i) q[i] = readReal(v[i], indexPath(p, i));
            const Quat raw(q[0], q[1], q[2], q[3]);
            const Real len = raw.norm();
            if (!(len > kMinQuaternionNorm) || !std::isfinite(len)) {
                fail(v, p, "must be a non-zero quaternion (it is normalised)");
            }
            b.orientation = Quat(raw.coeffs() / len);
        } else if (e.key == "euler_deg") {
            b.orientation = eulerDegrees(readVec3(v, p));
        } else if (e.key == "velocity") {
            b.velocity = readVec3(v, p);
            const std::string problem = speedProblem(b.velocity.stableNorm(), scene.world);
            if (!problem.empty()) fail(v, p, problem);
        } else if (e.key == "angular_velocity") {
            b.angular_velocity = readVec3(v, p);
            const std::string problem = spinProblem(b.angular_velocity.stableNorm(), scene.world);
            if (!problem.empty()) fail(v, p, problem);
        } else if (e.key == "mass") {
            b.mass = readReal(v, p);
            if (!(b.mass > 0)) fail(v, p, "must be > 0 (kg)");
            b.mass_entry = &e;
        } else if (e.key == "inertia") {
            b.inertia = readInertia(v, p);
            b.inertia_entry = &e;
        } else if (e.key == "density") {
            b.density = readReal(v, p);
            if (!(b.density > 0)) fail(v, p, "must be > 0 (kg/m^3)");
            b.density_entry = &e;
        } else if (e.key == "static") {
            b.is_static = readBool(v, p);
        } else if (e.key == "restitution") {
            b.restitution = readReal(v, p);
            if (!(b.restitution >= 0 && b.restitution <= 1)) fail(v, p, "must be in [0, 1]");
        } else if (e.key == "friction") {
            b.friction = readReal(v, p);
            if (!(b.friction >= 0)) fail(v, p, "must be >= 0");
        }
    }
    if (b.inertia_entry != nullptr && b.mass_entry == nullptr) {
        fail(b.inertia_entry->key_node, childPath(path, "inertia"),
             "needs 'mass' (the inertia of a given mass, kg m^2; with a density both come from "
             "the shape)");
    }
    if (b.is_static) {
        for (const Entry& e : es) {
            if (e.key == "velocity" || e.key == "angular_velocity") {
                fail(e.key_node, childPath(path, e.key), "a static body does not move");
            }
        }
    }
    return b;
}

// The body's shape and mass properties: geometry at density 1 (mass = volume), then scaled to
// the entry's mass or density. Problems are reported at `mass` or `density`, else at the shape's
// size key.
MassProperties SceneParser::bodyMassProperties(const std::vector<Entry>& es,
                                               const std::string& path, ShapeType type,
                                               const std::vector<std::string_view>& shape_keys,
                                               const BodyValues& b, const Scene& scene,
                                               Shape& shape) {
    MassProperties unit;
    const Entry* mass_at = b.mass_entry != nullptr      ? b.mass_entry
                           : b.density_entry != nullptr ? b.density_entry
                                                      : find(es, shape_keys.front());
    const std::string mass_path = childPath(path, mass_at->key);
    const YAML::Node mass_node = mass_at->value;
    if (type == ShapeType::ConvexHull || type == ShapeType::Mesh) {
        const PreparedShape& prepared =
            prepareMeshShape(type, b.file_entry->value.Scalar(), b.scale, *b.file_entry,
                             childPath(path, "file"), scene.world.mesh_bvh);
        shape = prepared.shape;
        unit = prepared.unit;
        noteMeshMass(prepared, b, path);
    } else {
        shape = type == ShapeType::Sphere ? Shape::sphere(b.radius)
                : type == ShapeType::Box  ? Shape::box(b.half_extents)
                                          : Shape::capsule(b.radius, b.half_height);
        const MassPropertiesOutput mp = computeMassProperties(shape, 1);
        if (mp.ok) {
            unit = mp.props;
        } else if (type == ShapeType::Box) {
            // A flat or degenerate box: only an explicit mass defines it. Thin-plate / rod limit
            // of the cuboid formula, with a floor so that the inertia stays invertible.
            if (b.mass_entry == nullptr) {
                fail(find(es, "half_extents")->value, childPath(path, "half_extents"),
                     "a box with zero volume needs 'mass' (a density gives it no mass)");
            }
            const Vec3 h2 = b.half_extents.cwiseProduct(b.half_extents);
            const Real l = std::max(b.half_extents.maxCoeff(), Real(1e-3));
            const Real floor2 = (kMinGyrationFraction * l) * (kMinGyrationFraction * l);
            const Vec3 moments = (Vec3(h2.y() + h2.z(), h2.z() + h2.x(), h2.x() + h2.y()) / 3)
                                     .cwiseMax(Vec3::Constant(floor2));
            unit.mass = 1;  // per kg: scaled by the mass below
            unit.inertia = moments.asDiagonal();
        } else {
            fail(mass_node, mass_path, mp.error);
        }
    }
    const Real scale_to = b.mass_entry != nullptr ? b.mass / unit.mass : b.density;
    MassProperties props = unit;
    props.mass = unit.mass * scale_to;
    props.inertia = unit.inertia * scale_to;
    if (b.mass_entry != nullptr) props.mass = b.mass;
    if (b.inertia_entry != nullptr) props.inertia = b.inertia;
    const Mat3 inv = props.inertia.inverse();
    if (!std::isfinite(props.mass) || !(props.mass > 0) || !props.inertia.allFinite() ||
        !inv.allFinite() || !(props.inertia.diagonal().minCoeff() > 0)) {
        std::ostringstream what;
        what << "gives degenerate mass properties (mass " << props.mass
             << " kg): the body is too small, too large, too light or too heavy";
        fail(mass_node, mass_path, what.str());
    }
    return props;
}

// Where a mesh body's mass properties come from when not from its own closed volume: a note for
// an open mesh; an error naming the ways out for a closed mesh whose volume is unusable, unless
// `mass` and `inertia` give them.
void SceneParser::noteMeshMass(const PreparedShape& prepared, const BodyValues& b,
                               const std::string& path) {
    const bool given = b.mass_entry != nullptr && b.inertia_entry != nullptr;
    const std::string file = b.file_entry->value.Scalar();
    if (!prepared.volume_error.empty() && !given) {
        fail(b.file_entry->key_node, childPath(path, "file"),
             "'" + file + "': " + prepared.volume_error +
                 "; use 'shape: hull' (its convex hull as the solid), or give 'mass' and "
                 "'inertia' (the centre of mass is then its convex hull's)");
    }
    if (prepared.boundary_edges == 0 && prepared.volume_error.empty()) return;
    std::string what = "mesh '" + file + "' ";
    if (prepared.boundary_edges > 0) {
        what += "is open (" + std::to_string(prepared.boundary_edges) + " boundary edge" +
                (prepared.boundary_edges == 1 ? "" : "s") + ")";
    } else {
        what += "gives no volume (" + prepared.volume_error + ")";
    }
    if (given) {
        what += "; centre of mass from its convex hull, mass and inertia as given";
    } else if (b.mass_entry != nullptr) {
        what += "; centre of mass and inertia per kg from its convex hull";
    } else {
        what += "; mass properties from its convex hull";
    }
    what += " (collision: its triangles, surface contact only)";
    notes_.push_back(formatMessage(file_, b.file_entry->key_node.Mark(), path + " (" + b.name + ")",
                                   what));
}

Mat3 SceneParser::readInertia(const YAML::Node& n, const std::string& path) const {
    const std::string expected =
        "expected [ix, iy, iz] (principal moments) or a 3x3 list of rows [[ixx, ixy, ixz], "
        "[ixy, iyy, iyz], [ixz, iyz, izz]], kg m^2";
    if (!n.IsSequence() || n.size() != 3) fail(n, path, expected);
    Mat3 inertia = Mat3::Zero();
    if (n[0].IsSequence()) {
        for (std::size_t r = 0; r < 3; ++r) {
            const YAML::Node row = n[r];
            if (!row.IsSequence() || row.size() != 3) fail(row, indexPath(path, r), expected);
            inertia.row(static_cast<Eigen::Index>(r)) = readVec3(row, indexPath(path, r));
        }
    } else {
        inertia.diagonal() = readVec3(n, path);
    }
    const std::string problem = inertiaProblem(inertia);
    if (!problem.empty()) fail(n, path, problem);
    return inertia;
}

Deformation SceneParser::readDeformation(const YAML::Node& n, const std::string& path) const {
    if (!n.IsMap())
        fail(n, path, "expected a mapping with keys: kind, amount, frequency, wavelength");
    const std::vector<Entry> es = entries(n, path, {"kind", "amount", "frequency", "wavelength"});
    Deformation d;
    const Entry& kind = require(es, "kind", n, path);
    const std::string k = readString(kind.value, childPath(path, "kind"));
    if (k == "bend") {
        d.kind = DeformKind::Bend;
    } else if (k == "twist") {
        d.kind = DeformKind::Twist;
    } else if (k == "wave") {
        d.kind = DeformKind::Wave;
    } else {
        fail(kind.value, childPath(path, "kind"),
             "unknown deformation '" + k + "' (expected one of: bend, twist, wave)");
    }
    const Entry& amount = require(es, "amount", n, path);
    d.amount = readReal(amount.value, childPath(path, "amount"));
    if (!std::isfinite(d.amount)) fail(amount.value, childPath(path, "amount"), "must be finite");
    const Entry& frequency = require(es, "frequency", n, path);
    d.frequency = readReal(frequency.value, childPath(path, "frequency"));
    if (!(d.frequency > 0 && d.frequency <= 1e3)) {
        fail(frequency.value, childPath(path, "frequency"), "must be in (0, 1000] (Hz)");
    }
    if (const Entry* w = find(es, "wavelength")) {
        if (d.kind != DeformKind::Wave)
            fail(w->key_node, childPath(path, "wavelength"), "applies to kind: wave only");
        d.wavelength = readReal(w->value, childPath(path, "wavelength"));
        if (!(d.wavelength > 0) || !std::isfinite(d.wavelength)) {
            fail(w->value, childPath(path, "wavelength"), "must be > 0 (m)");
        }
    }
    return d;
}

std::vector<Body> SceneParser::parseBody(const YAML::Node& n, std::size_t index,
                                         const Scene& scene) {
    const std::string path = indexPath("bodies", index);
    const std::vector<Entry> es =
        entries(n, path, std::vector<std::string_view>(std::begin(kBodyKeys), std::end(kBodyKeys)));
    // The shape first: it decides which keys apply.
    std::string shape_name;
    std::vector<std::string_view> shape_keys;
    const ShapeType type = bodyShape(es, n, path, shape_name, shape_keys);
    BodyValues values =
        readBodyValues(es, n, path, shape_name + std::to_string(index), shape_keys, scene);
    Shape shape;
    const MassProperties props =
        bodyMassProperties(es, path, type, shape_keys, values, scene, shape);

    Body body = makeBody(std::move(values.name), std::move(shape), props);
    body.restitution = values.restitution;
    body.friction = values.friction;
    if (const Entry* self = find(es, "self_collision")) {
        const std::string p = childPath(path, "self_collision");
        body.self_collision = readBool(self->value, p);
        if (body.self_collision && type != ShapeType::Mesh) {
            fail(self->value, p, "applies to mesh bodies only (shape: mesh)");
        }
    }
    if (const Entry* deform = find(es, "deform")) {
        const std::string p = childPath(path, "deform");
        if (type != ShapeType::Mesh) fail(deform->key_node, p, "applies to mesh bodies only");
        body.deform = readDeformation(deform->value, p);
    }
    auto place = [&props, is_static = values.is_static](Body& b, const Vec3& p, const Quat& q,
                                                          const Vec3& v, const Vec3& w) {
        b.position = p;
        b.orientation = q;
        b.linear_momentum = props.mass * v;
        const Mat3 r = q.toRotationMatrix();
        b.angular_momentum = r * props.inertia * r.transpose() * w;
        if (is_static) setStatic(b);
    };
    const Entry* repeat_entry = find(es, "repeat");
    if (repeat_entry == nullptr) {
        place(body, values.position, values.orientation, values.velocity,
              values.angular_velocity);
        return {std::move(body)};
    }
    return repeatBody(body, *repeat_entry, childPath(path, "repeat"), scene, place);
}


RepeatSpec SceneParser::readRepeat(const Entry& entry, const std::string& path,
                                   const Scene& scene) const {
    const YAML::Node& n = entry.value;
    if (!n.IsMap())
        fail(n, path,
             "expected a mapping with keys: " +
                 join({"count", "seed", "region", "speed", "spin", "random_orientation",
                       "separated"}));
    const std::vector<Entry> es = entries(
        n, path, std::vector<std::string_view>(std::begin(kRepeatKeys), std::end(kRepeatKeys)));
    RepeatSpec r;
    r.region = scene.world.bounds;
    r.node = n;
    const Entry& count_entry = require(es, "count", n, path);
    r.count = readInt(count_entry.value, childPath(path, "count"));
    if (r.count < 1 || r.count > kMaxRepeat) {
        fail(count_entry.value, childPath(path, "count"),
             "must be in 1.." + std::to_string(kMaxRepeat));
    }
    if (scene.bodies.size() + static_cast<std::size_t>(r.count) > kMaxBodies) {
        fail(count_entry.value, childPath(path, "count"),
             std::to_string(r.count) + " more bodies after " +
                 std::to_string(scene.bodies.size()) + " would pass the limit of " +
                 std::to_string(kMaxBodies) + " bodies in a scene");
    }
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "seed") {
            const int seed = readInt(e.value, p);
            if (seed < 0) fail(e.value, p, "must be >= 0");
            r.seed = static_cast<std::uint64_t>(seed);
        } else if (e.key == "region") {
            const std::vector<Entry> re = entries(e.value, p, {"min", "max"});
            r.region.min = readVec3(require(re, "min", e.value, p).value, childPath(p, "min"));
            r.region.max = readVec3(require(re, "max", e.value, p).value, childPath(p, "max"));
            for (int a = 0; a < 3; ++a) {
                if (!(r.region.min[a] <= r.region.max[a])) {
                    fail(e.value, p, "min must be <= max on every axis");
                }
            }
            if (!scene.world.bounds.contains(r.region.min) ||
                !scene.world.bounds.contains(r.region.max)) {
                fail(e.value, p, "must lie inside the world bounds");
            }
        } else if (e.key == "speed") {
            r.speed = readReal(e.value, p);
            if (!(r.speed >= 0)) fail(e.value, p, "must be >= 0 (m/s)");
            const std::string problem = speedProblem(r.speed, scene.world);
            if (!problem.empty()) fail(e.value, p, problem);
        } else if (e.key == "spin") {
            r.spin = readReal(e.value, p);
            if (!(r.spin >= 0)) fail(e.value, p, "must be >= 0 (rad/s)");
            const std::string problem = spinProblem(r.spin, scene.world);
            if (!problem.empty()) fail(e.value, p, problem);
        } else if (e.key == "random_orientation") {
            r.random_orientation = readBool(e.value, p);
        } else if (e.key == "separated") {
            r.separated = readBool(e.value, p);
        }
    }
    return r;
}

void SceneParser::requireRoomToSeparate(const RepeatSpec& r, Real radius,
                                        const std::string& path) const {
    // Random sequential addition of equal spheres jams at a volume fraction of about 0.38 in
    // three dimensions (0.55 of the area in two, 0.75 of the length in one, each below 0.4 as a
    // fraction of the region grown by the radius): asking for more than kMaxRepeatPacking of the
    // grown region cannot succeed, so it is refused before any try.
    const Vec3 grown = r.region.max - r.region.min + Vec3::Constant(2 * radius);
    const double room = double(grown.x()) * double(grown.y()) * double(grown.z());
    const double need = double(r.count) * 4.0 / 3.0 * std::numbers::pi * std::pow(double(radius), 3);
    if (need > kMaxRepeatPacking * room) {
        fail(r.node, path,
             std::to_string(r.count) + " bounding spheres of radius " + formatLimit(radius) +
                 " fill " + std::to_string(std::llround(100 * need / room)) +
                 "% of the region (grown by the radius); randomly placed spheres stay apart "
                 "only below about 38%: enlarge region, lower count, or set separated: false");
    }
}

template <typename Place>
std::vector<Body> SceneParser::repeatBody(const Body& base, const Entry& entry,
                                          const std::string& path, const Scene& scene,
                                          Place&& place) const {
    const RepeatSpec r = readRepeat(entry, path, scene);
    // splitmix64: the same bodies from the same seed on every platform.
    std::uint64_t state = r.seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
    auto uniform = [&state]() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        return Real(z >> 11) * Real(0x1.0p-53);
    };
    auto direction = [&uniform]() {
        // Uniform on the sphere: z uniform in [-1, 1], azimuth uniform (Archimedes).
        const Real z = 2 * uniform() - 1;
        const Real phi = 2 * std::numbers::pi_v<Real> * uniform();
        const Real rad = std::sqrt(std::max(Real(0), 1 - z * z));
        return Vec3(rad * std::cos(phi), rad * std::sin(phi), z);
    };
    // Bounding radius about the centre of mass, whatever the orientation drawn later.
    const Real radius = base.local_bounds.sphere.center.norm() + base.local_bounds.sphere.radius;
    std::optional<SeparatedPlacement> placement;
    if (r.separated) {
        requireRoomToSeparate(r, radius, path);
        placement.emplace(scene.bodies, radius, r.region);
    }
    const std::int64_t max_attempts =
        kRepeatAttemptsPerBody * std::int64_t(r.count) + kRepeatAttemptsReserve;
    std::int64_t attempts_left = max_attempts;
    std::vector<Body> out;
    out.reserve(static_cast<std::size_t>(r.count));
    for (int k = 0; k < r.count; ++k) {
        Body b = base;
        b.name = base.name + "_" + std::to_string(k);
        Vec3 p;
        do {
            if (placement && --attempts_left < 0) {
                fail(r.node, path,
                     "placed " + std::to_string(k) + " of " + std::to_string(r.count) +
                         " bodies apart from each other and from the bodies listed before, "
                         "then found no free place in " +
                         std::to_string(max_attempts) +
                         " random tries (bounding spheres of radius " + formatLimit(radius) +
                         "): enlarge region, lower count, or set separated: false");
            }
            const Vec3 t(uniform(), uniform(), uniform());
            p = r.region.min + (r.region.max - r.region.min).cwiseProduct(t);
        } while (placement && !placement->fits(p));
        if (placement) placement->add(p);
        Quat q = Quat::Identity();
        if (r.random_orientation) {
            // Shoemake's uniform random rotation.
            const Real u1 = uniform(), u2 = uniform(), u3 = uniform();
            const Real a = std::sqrt(1 - u1), c = std::sqrt(u1);
            const Real tau = 2 * std::numbers::pi_v<Real>;
            q = Quat(a * std::sin(tau * u2), a * std::cos(tau * u2), c * std::sin(tau * u3),
                     c * std::cos(tau * u3))
                    .normalized();
        }
        const Vec3 v = direction() * (r.speed * uniform());
        const Vec3 w = direction() * (r.spin * uniform());
        place(b, p, q, v, w);
        out.push_back(std::move(b));
    }
    return out;
}

}  // namespace engine::scene_parsing

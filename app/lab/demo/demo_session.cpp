// app/lab/demo/demo_session.cpp -- see demo_session.h.
#include "demo/demo_session.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include "engine/volume_overlaps.h"
#include "render/camera_moves.h"

namespace app {

DemoSession::DemoSession(const engine::Scene& scene, bool structure)
    : scene_(scene), world_(engine::makeWorld(scene)), broad_phase_(scene.world.broad_phase) {
    view_.draw = engine::drawSettingsFor(scene.draw, world_);
    view_.structure = scene.draw.structure || structure;
    view_.camera = scene.camera;
    view_.volumes_chosen = scene.draw.volumes_given;
    keepSnapshot();
}

DemoSession::DemoSession(const engine::Scene& scene, bool structure,
                         const engine::Recording& recording)
    : DemoSession(scene, structure) {
    recording_ = &recording;
    snapshots_.clear();
    placeRecorded(0);
}

void DemoSession::placeRecorded(int frame) {
    const engine::RecordedFrame f = recording_->frame(frame);
    if (!broad_phase_chosen_ && f.broad_phase != broad_phase_) {
        world_.setBroadPhase(f.broad_phase);
        broad_phase_ = f.broad_phase;
        followBroadPhase();
    }
    // After a command chose another broad phase, the recorded counters (of the recorded one's
    // step) are not this one's: the HUD shows the detection's, and the pairs, and so the hash,
    // may be another volume kind's.
    const bool recorded = f.broad_phase == broad_phase_;
    world_.place(f.state, f.impacts,
                 recorded ? std::optional<engine::StepStats>(f.counters) : std::nullopt);
    if (recorded && world_.stateHash() != f.state_hash) {
        throw engine::RecordingError(
            recording_->file().string() + ": frame " + std::to_string(frame) +
            ": the recorded state, placed and detected, does not hash to its recorded hash (a "
            "recording of another build of cdlab, whose detection differs)");
    }
    frame_ = frame;
}

void DemoSession::followBroadPhase() {
    // Only the volumes follow the broad phase: the layers a user switched on (labels, contacts,
    // the hierarchy) stay as they are.
    if (!view_.volumes_chosen) view_.draw = engine::drawSettingsFor(view_.draw, world_);
}

engine::CameraSettings DemoSession::camera() const {
    if (!view_.follow) return view_.camera;
    return render::lookAtPoint(view_.camera,
                               world_.bodies()[std::size_t(*view_.follow)].position);
}

render::FrameOptions DemoSession::frameOptions() const {
    render::FrameOptions options;
    options.draw = view_.draw;
    options.draw_structure = view_.structure;
    options.selected = view_.selected;
    return options;
}

std::string DemoSession::hudText(bool paused, bool timing) const {
    if (!view_.draw.hud) return {};
    std::string text = render::hudLine(world_, frame_, timing && !paused);
    if (paused) text = "PAUSED  " + text;
    if (view_.selected) text += "\n" + selectionLine(world_, *view_.selected);
    return text;
}

void DemoSession::keepSnapshot() {
    if (frame_ % interval_ != 0 || snapshots_.count(frame_)) return;
    snapshots_.emplace(frame_, world_.snapshot());
    if (int(snapshots_.size()) <= kMaxSnapshots) return;
    interval_ *= 2;
    for (auto it = snapshots_.begin(); it != snapshots_.end();) {
        it = it->first % interval_ == 0 ? std::next(it) : snapshots_.erase(it);
    }
}

bool DemoSession::advance() {
    if (frame_ >= lastFrame()) return false;
    if (recording_) {
        placeRecorded(frame_ + 1);
        return true;
    }
    for (int s = 0; s < scene_.steps_per_frame; ++s) {
        world_.step();
        if (on_step) on_step(world_);
    }
    ++frame_;
    keepSnapshot();
    return true;
}

void DemoSession::goTo(int frame) {
    if (frame < 0 || frame > lastFrame()) {
        throw std::out_of_range("frame " + std::to_string(frame) + " is outside the run");
    }
    if (recording_) {
        if (frame != frame_) placeRecorded(frame);
        return;
    }
    if (frame < frame_) {
        // The nearest snapshot at or before `frame` (frame 0's is always kept).
        auto it = std::prev(snapshots_.upper_bound(frame));
        world_.restore(it->second);
        frame_ = it->first;
        if (world_.broadPhase().name() != broad_phase_) world_.setBroadPhase(broad_phase_);
    }
    while (frame_ < frame) advance();
}

void DemoSession::show(engine::DemoLayer layer, bool on) {
    using engine::DemoLayer;
    engine::DrawSettings& d = view_.draw;
    switch (layer) {
        case DemoLayer::Sphere: d.sphere = on; break;
        case DemoLayer::Aabb: d.aabb = on; break;
        case DemoLayer::Obb: d.obb = on; break;
        case DemoLayer::Kdop6: d.kdop[0] = on; break;
        case DemoLayer::Kdop14: d.kdop[1] = on; break;
        case DemoLayer::Kdop18: d.kdop[2] = on; break;
        case DemoLayer::Kdop26: d.kdop[3] = on; break;
        case DemoLayer::Hierarchy:
            d.bvh_depth = !on ? -1 : scene_.draw.bvh_depth >= 0 ? scene_.draw.bvh_depth : 2;
            break;
        case DemoLayer::Structure: view_.structure = on; break;
        case DemoLayer::Contacts: d.contacts = on; break;
        case DemoLayer::Labels: d.labels = on; break;
        case DemoLayer::Bounds: d.bounds = on; break;
        case DemoLayer::Bodies: d.bodies = on; break;
        case DemoLayer::Hud: d.hud = on; break;
    }
    if (layer <= DemoLayer::Kdop26) view_.volumes_chosen = true;
}

bool DemoSession::shows(engine::DemoLayer layer) const {
    using engine::DemoLayer;
    const engine::DrawSettings& d = view_.draw;
    switch (layer) {
        case DemoLayer::Sphere: return d.sphere;
        case DemoLayer::Aabb: return d.aabb;
        case DemoLayer::Obb: return d.obb;
        case DemoLayer::Kdop6: return d.kdop[0];
        case DemoLayer::Kdop14: return d.kdop[1];
        case DemoLayer::Kdop18: return d.kdop[2];
        case DemoLayer::Kdop26: return d.kdop[3];
        case DemoLayer::Hierarchy: return d.bvh_depth >= 0;
        case DemoLayer::Structure: return view_.structure;
        case DemoLayer::Contacts: return d.contacts;
        case DemoLayer::Labels: return d.labels;
        case DemoLayer::Bounds: return d.bounds;
        case DemoLayer::Bodies: return d.bodies;
        case DemoLayer::Hud: return d.hud;
    }
    return false;
}

void DemoSession::moveCamera(const engine::CameraCommand& c) {
    if (c.reset) {
        view_.camera = scene_.camera;
        view_.follow.reset();
    }
    // Moves while following turn about the body where it is now.
    if (c.orbit || c.zoom || c.pan) view_.camera = camera();
    if (c.orbit) view_.camera = render::orbitCamera(view_.camera, (*c.orbit)[0], (*c.orbit)[1]);
    if (c.zoom) view_.camera = render::zoomCamera(view_.camera, *c.zoom);
    if (c.pan) view_.camera = render::panCamera(view_.camera, (*c.pan)[0], (*c.pan)[1]);
    if (c.follow) view_.follow = *c.follow;
}

std::string DemoSession::apply(const engine::DemoCommands& c,
                               const std::function<void()>& reached) {
    // Everything that can be refused is checked before anything changes.
    int target = frame_;
    if (c.step) target += *c.step;
    if (c.step && (target < 0 || target > lastFrame())) {
        return "step " + std::to_string(*c.step) + " from frame " + std::to_string(frame_) +
               " leaves the run's frames 0.." + std::to_string(lastFrame());
    }
    if (c.seek && (*c.seek < 0 || *c.seek > lastFrame())) {
        return "seek to frame " + std::to_string(*c.seek) + " leaves the run's frames 0.." +
               std::to_string(lastFrame());
    }
    for (const auto& id : {c.select.value_or(std::nullopt),
                           c.camera && c.camera->follow ? *c.camera->follow : std::nullopt}) {
        if (id && (*id < 0 || std::size_t(*id) >= world_.bodies().size())) {
            return "no body " + std::to_string(*id);
        }
    }

    if (c.broad_phase) broad_phase_chosen_ = true;
    if (c.broad_phase && *c.broad_phase != broad_phase_) {
        world_.setBroadPhase(*c.broad_phase);
        broad_phase_ = *c.broad_phase;
        // The frames ahead were simulated with the other broad phase: their snapshots go.
        snapshots_.erase(snapshots_.upper_bound(frame_), snapshots_.end());
        followBroadPhase();
    }
    for (const engine::DemoLayer l : c.show) show(l, true);
    for (const engine::DemoLayer l : c.hide) show(l, false);
    if (c.select) view_.selected = *c.select;
    if (c.camera) moveCamera(*c.camera);
    if (c.speed) view_.speed = double(*c.speed);
    if (c.playing) playing_ = *c.playing;
    if (c.step) {
        const int dir = *c.step > 0 ? 1 : -1;
        while (frame_ != target) {
            goTo(frame_ + dir);
            if (reached) reached();
        }
    }
    if (c.seek) {
        goTo(*c.seek);
        if (reached) reached();
    }
    return "";
}

std::string selectionLine(const engine::World& world, engine::BodyId id, int max_names) {
    const auto bodies = world.bodies();
    if (id < 0 || std::size_t(id) >= bodies.size()) return "";
    std::set<engine::BodyId> touching;
    // The partners of `id` in `pairs` by name, those in `touching` left out.
    auto partners = [&](std::span<const collision::ProxyPair> pairs) {
        std::string list;
        int named = 0, more = 0;
        for (const collision::ProxyPair& p : pairs) {
            if (p.a != id && p.b != id) continue;
            const engine::BodyId other = p.a == id ? p.b : p.a;
            if (touching.count(other)) continue;
            if (named == max_names) {
                ++more;
                continue;
            }
            list += (named++ ? ", " : "") + bodies[std::size_t(other)].name;
        }
        if (more) list += " and " + std::to_string(more) + " more";
        return list;
    };
    const engine::Body& b = bodies[std::size_t(id)];
    std::string line = "selected " + b.name + " (" +
                       std::string(collision::shapeTypeName(b.shape.type)) + ")";
    const std::string colliding = partners(world.collidingPairs());
    for (const collision::ProxyPair& p : world.collidingPairs()) {
        if (p.a == id || p.b == id) touching.insert(p.a == id ? p.b : p.a);
    }
    const std::string flagged = partners(world.flaggedPairs());
    if (colliding.empty() && flagged.empty()) return line + ": apart";
    if (!colliding.empty()) line += ": colliding with " + colliding;
    if (!flagged.empty()) line += (colliding.empty() ? ": " : "; ") + std::string("flagged with ") + flagged;
    return line;
}

}  // namespace app

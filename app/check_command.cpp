// app/check_command.cpp -- grading a run against the scene's `expect:` section.
// Every expectation is observed on the same single run: frame 0 is the initial state, frame k is
// after k * steps_per_frame steps. Broad-phase agreement and energy are checked on every step,
// pair states and colours on every frame they name. Rows come out in a fixed order (the order of
// the expect keys below, then file order), so two checks of the same scene print the same table.
#include "check_command.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>
#include <unistd.h>
#include <vector>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "broadphase_check.h"
#include "collision/broadphase/broad_phase.h"
#include "command.h"
#include "exit_codes.h"
#include "output_files.h"
#include "pause_dump.h"
#include "render/image.h"
#include "render/renderer.h"

namespace app {

namespace fs = std::filesystem;

namespace {

// A body counts as moving when its centre got this fraction of the world-bounds diagonal away
// from where it started, and as rotating when its orientation got kMinRotationRad away, at any
// frame of the run (so a body that comes back still counts).
constexpr double kMinDisplacementFraction = 1e-3;
constexpr double kMinRotationRad = 1.0 * 3.14159265358979323846 / 180.0;
// A pixel shows a state colour when every RGB8 channel is within this of the colour: wireframe
// edges blended by the 2x2 supersampling filter with the background fall outside it.
constexpr int kColorTolerance = 40;
// Energies below this (J) count as zero when the drift is made relative.
constexpr double kMinReferenceEnergy = 1e-12;

std::string frameText(const engine::FrameRange& r) {
    return r.first == r.last ? "frame " + std::to_string(r.first)
                             : "frames " + std::to_string(r.first) + ".." + std::to_string(r.last);
}

std::string colorName(engine::BodyState s) {
    switch (s) {
        case engine::BodyState::Apart:
            return "green";
        case engine::BodyState::Flagged:
            return "yellow";
        case engine::BodyState::Colliding:
            return "red";
    }
    return "?";
}

bool hasPair(std::span<const collision::ProxyPair> pairs, engine::BodyId a, engine::BodyId b) {
    const collision::ProxyPair key{std::min(a, b), std::max(a, b)};
    return std::binary_search(pairs.begin(), pairs.end(), key);
}

// Kinetic plus potential energy in uniform gravity, J (potential zero at the origin).
double totalEnergy(const engine::World& world) {
    double e = 0;
    const engine::Vec3 g = world.settings().gravity;
    for (const engine::Body& b : world.bodies()) {
        e += double(b.kineticEnergy()) - double(b.mass) * double(g.dot(b.position));
    }
    return e;
}

// Pixels of each state colour in an image, indexed by BodyState.
std::array<long, 3> countStateColors(const render::Image& image) {
    std::array<std::array<int, 3>, 3> rgb{};
    for (int s = 0; s < 3; ++s) {
        const collision::Color c = render::stateColor(static_cast<engine::BodyState>(s));
        rgb[s] = {int(std::lround(c.r * 255)), int(std::lround(c.g * 255)),
                  int(std::lround(c.b * 255))};
    }
    std::array<long, 3> counts{};
    for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) {
        for (int s = 0; s < 3; ++s) {
            if (std::abs(image.rgb[i] - rgb[s][0]) <= kColorTolerance &&
                std::abs(image.rgb[i + 1] - rgb[s][1]) <= kColorTolerance &&
                std::abs(image.rgb[i + 2] - rgb[s][2]) <= kColorTolerance) {
                ++counts[s];
            }
        }
    }
    return counts;
}

// Feeds a broad phase the world's volumes: inserts new proxies, moves the others.
void feed(collision::BroadPhase& phase, std::size_t& inserted,
          std::span<const collision::ProxyVolumes> volumes) {
    for (std::size_t i = 0; i < volumes.size(); ++i) {
        const auto id = static_cast<collision::ProxyId>(i);
        if (i < inserted) {
            phase.move(id, volumes[i]);
        } else {
            phase.insert(id, volumes[i]);
        }
    }
    inserted = volumes.size();
}

// Brute-force references, one per volume type however many broad phases use it.
struct Reference {
    std::string name;
    std::unique_ptr<collision::BroadPhase> phase;
    std::vector<collision::ProxyPair> pairs;
    std::size_t inserted = 0;
};

// One broad phase from `expect.broadphases`, fed the world's volumes beside its reference.
struct ExtraBroadPhase {
    std::string name;
    std::size_t reference = 0;  // index into the references
    std::unique_ptr<collision::BroadPhase> phase;
    std::vector<collision::ProxyPair> got;
    std::size_t inserted = 0;
    std::string first_mismatch;  // empty while they agree
};

// a's centre in b's OBB frame (coordinates along b's box axes, relative to its centre).
engine::Vec3 localCentre(const engine::World& world, engine::BodyId a, engine::BodyId b) {
    const collision::Obb& box = world.volumes()[b].obb;
    return box.axes.transpose() * (world.bodies()[a].position - box.center);
}

// Tunnelling: the axis of b's box along which a starts farthest out and on which side; a has
// passed once its centre is beyond the box on the other side.
struct TunnelTracker {
    int axis = 0;
    double side = 1;
    bool starts_outside = false;
    bool passed = false;
    int passed_frame = -1;
};

struct ToiTracker {
    bool seen = false;
    double time = 0;
    bool failed = false;  // the first event came from a query that hit its cap
};

struct RestTracker {
    engine::Vec3 origin = engine::Vec3::Zero();
    double max_displacement = 0;
    int displacement_frame = -1;
    double max_speed = 0;
    int speed_frame = -1;
};

struct PairTracker {
    bool every_held = true;
    int first_violation = -1;
    bool any_held = false;
    int frames_seen = 0;
};

std::string verifyPauseDump(const fs::path& dir, int frame, const engine::Scene& scene) {
    const fs::path png = dir / ("pause_" + std::to_string(frame) + ".png");
    const fs::path json = dir / ("pause_" + std::to_string(frame) + ".json");
    std::error_code ec;
    if (!fs::is_regular_file(png, ec)) return png.string() + " was not written";
    if (!fs::is_regular_file(json, ec)) return json.string() + " was not written";
    try {
        const render::Image image = render::readPng(png);
        if (image.width != scene.output.width || image.height != scene.output.height) {
            return png.string() + " is " + std::to_string(image.width) + "x" +
                   std::to_string(image.height) + ", expected " +
                   std::to_string(scene.output.width) + "x" + std::to_string(scene.output.height);
        }
    } catch (const render::RenderError& e) {
        return std::string("unreadable PNG: ") + e.what();
    }
    std::ifstream in(json, std::ios::binary);
    const nlohmann::json dump = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (dump.is_discarded()) return json.string() + " is not valid JSON";
    if (!dump.contains("frame") || dump["frame"] != frame) {
        return json.string() + " does not name frame " + std::to_string(frame);
    }
    if (!dump.contains("bodies") || !dump["bodies"].is_array() ||
        dump["bodies"].size() != scene.bodies.size()) {
        return json.string() + " does not list all " + std::to_string(scene.bodies.size()) +
               " bodies";
    }
    return {};
}

std::string formatDouble(double v, int digits = 3) {
    std::ostringstream s;
    s.precision(digits);
    s << v;
    return s.str();
}

}  // namespace

std::vector<CheckRow> checkScene(const engine::Scene& scene, int frames, const fs::path& dump_dir) {
    const engine::Expectations& ex = scene.expect;
    std::vector<CheckRow> rows;
    if (!ex.present) {
        rows.push_back({"expect", false, "the scene has no 'expect:' section"});
        return rows;
    }

    engine::World world = engine::makeWorld(scene);
    const std::size_t n = world.bodies().size();
    std::vector<engine::Vec3> start_position(n);
    std::vector<engine::Quat> start_orientation(n);
    for (std::size_t i = 0; i < n; ++i) {
        start_position[i] = world.bodies()[i].position;
        start_orientation[i] = world.bodies()[i].orientation;
    }
    std::vector<double> max_displacement(n, 0.0);
    std::vector<double> max_rotation(n, 0.0);

    std::vector<Reference> references;
    std::vector<ExtraBroadPhase> extra;
    for (const std::string& name : ex.broad_phases) {
        const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
        ExtraBroadPhase e;
        e.name = name;
        e.phase = entry->create();
        e.reference = references.size();
        for (std::size_t r = 0; r < references.size(); ++r) {
            if (references[r].name == entry->reference) e.reference = r;
        }
        if (e.reference == references.size()) {
            references.push_back({std::string(entry->reference),
                                  collision::findBroadPhase(entry->reference)->create(),
                                  {},
                                  0});
        }
        extra.push_back(std::move(e));
    }
    const double energy0 = totalEnergy(world);
    double max_drift = 0;
    int max_drift_frame = 0;
    double max_rise = 0;
    int max_rise_frame = 0;
    std::vector<TunnelTracker> tunnels(ex.tunnelling.size());
    for (std::size_t k = 0; k < ex.tunnelling.size(); ++k) {
        const engine::TunnelExpectation& t = ex.tunnelling[k];
        const engine::Vec3 c = localCentre(world, t.a, t.b);
        const engine::Vec3 h = world.volumes()[t.b].obb.half_extents;
        double best = -1;
        for (int axis = 0; axis < 3; ++axis) {
            const double out = std::abs(double(c[axis])) - double(h[axis]);
            const double relative = out / std::max(double(h[axis]), 1e-300);
            if (out > 0 && relative > best) {
                best = relative;
                tunnels[k].axis = axis;
                tunnels[k].side = c[axis] >= 0 ? 1.0 : -1.0;
                tunnels[k].starts_outside = true;
            }
        }
    }
    std::vector<ToiTracker> tois(ex.toi.size());
    std::vector<RestTracker> rests(ex.rest.size());
    std::vector<PairTracker> pair_state(ex.pairs.size());
    std::vector<std::array<long, 3>> color_counts(ex.colors.size());
    std::vector<std::string> dump_problems(ex.pause_dumps.size());

    std::unique_ptr<render::Renderer> renderer;
    auto getRenderer = [&]() -> render::Renderer& {
        if (!renderer) {
            renderer = std::make_unique<render::Renderer>(scene.output.width, scene.output.height);
        }
        return *renderer;
    };

    auto observeStep = [&](int frame) {
        collision::BroadPhaseCounters ignored;
        for (Reference& r : references) {
            feed(*r.phase, r.inserted, world.volumes());
            r.phase->findPairs(r.pairs, ignored);
        }
        for (ExtraBroadPhase& e : extra) {
            if (!e.first_mismatch.empty()) continue;  // report the first mismatch only
            feed(*e.phase, e.inserted, world.volumes());
            e.phase->findPairs(e.got, ignored);
            std::string report =
                describePairMismatch(e.name, references[e.reference].name, e.got,
                                     references[e.reference].pairs, world.bodies());
            if (report.empty()) continue;
            std::replace(report.begin(), report.end(), '\n', ';');
            e.first_mismatch = "differs at frame " + std::to_string(frame) + ", step " +
                               std::to_string(world.stepCount()) + ": " + report;
        }
        if (ex.energy_drift_max || ex.energy_rise_max) {
            const double change =
                (totalEnergy(world) - energy0) / std::max(std::abs(energy0), kMinReferenceEnergy);
            if (std::abs(change) > max_drift) {
                max_drift = std::abs(change);
                max_drift_frame = frame;
            }
            if (change > max_rise) {
                max_rise = change;
                max_rise_frame = frame;
            }
        }
        for (std::size_t k = 0; k < ex.tunnelling.size(); ++k) {
            TunnelTracker& t = tunnels[k];
            if (!t.starts_outside || t.passed) continue;
            const engine::TunnelExpectation& te = ex.tunnelling[k];
            const double c = localCentre(world, te.a, te.b)[t.axis];
            if (t.side * c < -double(world.volumes()[te.b].obb.half_extents[t.axis])) {
                t.passed = true;
                t.passed_frame = frame;
            }
        }
    };
    // The CCD stage's events of the step that just ran, as simulated times.
    auto observeToi = [&](double step_start) {
        const double dt = double(world.settings().time_step);
        for (const engine::ToiEvent& e : world.toiEvents()) {
            for (std::size_t k = 0; k < ex.toi.size(); ++k) {
                const engine::ToiExpectation& te = ex.toi[k];
                if (tois[k].seen || std::min(te.a, te.b) != std::min(e.a, e.b) ||
                    std::max(te.a, te.b) != std::max(e.a, e.b)) {
                    continue;
                }
                tois[k] = {true, step_start + double(e.t) * dt, e.failed};
            }
        }
    };

    for (int frame = 0; frame < frames; ++frame) {
        if (frame == 0) {
            observeStep(0);
        } else {
            for (int s = 0; s < scene.steps_per_frame; ++s) {
                const double step_start = double(world.time());
                world.step();
                observeStep(frame);
                observeToi(step_start);
            }
        }
        for (std::size_t i = 0; i < n; ++i) {
            const engine::Body& b = world.bodies()[i];
            max_displacement[i] =
                std::max(max_displacement[i], double((b.position - start_position[i]).norm()));
            max_rotation[i] = std::max(max_rotation[i],
                                       double(b.orientation.angularDistance(start_orientation[i])));
        }
        for (std::size_t k = 0; k < ex.rest.size(); ++k) {
            const engine::RestExpectation& r = ex.rest[k];
            if (frame < r.frames.first || frame > r.frames.last) continue;
            const engine::Body& b = world.bodies()[r.body];
            RestTracker& t = rests[k];
            if (frame == r.frames.first) t.origin = b.position;
            const double d = double((b.position - t.origin).norm());
            const double v = double(b.velocity().norm());
            if (d > t.max_displacement || t.displacement_frame < 0) {
                t.max_displacement = d;
                t.displacement_frame = frame;
            }
            if (v > t.max_speed || t.speed_frame < 0) {
                t.max_speed = v;
                t.speed_frame = frame;
            }
        }
        for (std::size_t k = 0; k < ex.pairs.size(); ++k) {
            const engine::PairExpectation& p = ex.pairs[k];
            if (frame < p.frames.first || frame > p.frames.last) continue;
            const bool flagged = hasPair(world.flaggedPairs(), p.a, p.b);
            const bool colliding = hasPair(world.collidingPairs(), p.a, p.b);
            const bool holds = (!p.colliding || *p.colliding == colliding) &&
                               (!p.flagged || *p.flagged == flagged);
            PairTracker& t = pair_state[k];
            ++t.frames_seen;
            t.any_held = t.any_held || holds;
            if (!holds && t.every_held) {
                t.every_held = false;
                t.first_violation = frame;
            }
        }
        for (std::size_t k = 0; k < ex.colors.size(); ++k) {
            if (ex.colors[k].frame != frame) continue;
            // No HUD: its legend shows every colour whatever the state.
            render::FrameOptions options;
            options.draw = scene.draw;
            options.draw.hud = false;
            color_counts[k] = countStateColors(getRenderer().render(world, scene.camera, options));
        }
        for (std::size_t k = 0; k < ex.pause_dumps.size(); ++k) {
            if (ex.pause_dumps[k] != frame) continue;
            // The same dump `cdlab run --pause-at` writes: every volume drawn, plus the JSON.
            render::FrameOptions options;
            options.draw = scene.draw;
            options.draw.sphere = options.draw.aabb = options.draw.obb = true;
            options.hud_text = "PAUSED  " + render::hudLine(world, frame, false);
            const std::string stem = "pause_" + std::to_string(frame);
            render::writePng(dump_dir / (stem + ".png"),
                             getRenderer().render(world, scene.camera, options));
            writeTextAtomically(dump_dir / (stem + ".json"), pauseDumpJson(world, frame));
        }
    }

    // Rows, in a fixed order.
    if (ex.min_bodies) {
        CheckRow r{"at least " + std::to_string(*ex.min_bodies) + " bodies",
                   n >= std::size_t(*ex.min_bodies), ""};
        if (!r.pass) r.reason = "the scene has " + std::to_string(n) + " bodies";
        rows.push_back(r);
    }
    if (ex.min_moving_rotating) {
        const double diagonal = double((scene.world.bounds.max - scene.world.bounds.min).norm());
        int count = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (max_displacement[i] > kMinDisplacementFraction * diagonal &&
                max_rotation[i] > kMinRotationRad) {
                ++count;
            }
        }
        CheckRow r{
            "at least " + std::to_string(*ex.min_moving_rotating) + " bodies moving and rotating",
            count >= *ex.min_moving_rotating, ""};
        if (!r.pass) {
            r.reason = std::to_string(count) + " of " + std::to_string(n) +
                       " bodies both moved and rotated (> 1 degree) in " + std::to_string(frames) +
                       " frames";
        }
        rows.push_back(r);
    }
    for (const ExtraBroadPhase& e : extra) {
        CheckRow r{
            "broad phase " + e.name + " equals " + references[e.reference].name + " every step",
            e.first_mismatch.empty(), e.first_mismatch};
        rows.push_back(r);
    }
    if (ex.energy_drift_max) {
        CheckRow r{"energy drift <= " + formatDouble(double(*ex.energy_drift_max)),
                   max_drift <= double(*ex.energy_drift_max), ""};
        if (!r.pass) {
            r.reason = "relative drift " + formatDouble(max_drift) + " at frame " +
                       std::to_string(max_drift_frame) + " (E0 = " + formatDouble(energy0) + " J)";
        }
        rows.push_back(r);
    }
    if (ex.energy_rise_max) {
        CheckRow r{"energy rise <= " + formatDouble(double(*ex.energy_rise_max)),
                   max_rise <= double(*ex.energy_rise_max), ""};
        if (!r.pass) {
            r.reason = "energy rose by " + formatDouble(max_rise) + " of E0 at frame " +
                       std::to_string(max_rise_frame) + " (E0 = " + formatDouble(energy0) + " J)";
        }
        rows.push_back(r);
    }
    for (std::size_t k = 0; k < ex.tunnelling.size(); ++k) {
        const engine::TunnelExpectation& te = ex.tunnelling[k];
        const TunnelTracker& t = tunnels[k];
        CheckRow r{
            te.a_name + (te.passes ? " passes through " : " never passes through ") + te.b_name,
            false, ""};
        if (!t.starts_outside) {
            r.reason = te.a_name + "'s centre starts inside " + te.b_name + "'s box";
        } else if (te.passes) {
            r.pass = t.passed;
            if (!r.pass) r.reason = "it never got to the other side";
        } else {
            r.pass = !t.passed;
            if (!r.pass) r.reason = "on the other side at frame " + std::to_string(t.passed_frame);
        }
        rows.push_back(r);
    }
    for (std::size_t k = 0; k < ex.toi.size(); ++k) {
        const engine::ToiExpectation& te = ex.toi[k];
        const ToiTracker& t = tois[k];
        CheckRow r{"first time of impact " + te.a_name + " / " + te.b_name + " in [" +
                       formatDouble(double(te.time - te.tolerance), 8) + ", " +
                       formatDouble(double(te.time), 8) + "] s",
                   false, ""};
        std::ostringstream got;
        got.precision(9);
        got << t.time;
        if (!t.seen) {
            r.reason = "the CCD stage reported no time of impact for the pair";
        } else if (t.failed) {
            r.reason = "the query hit its iteration cap (Failed) at t = " + got.str() + " s";
        } else if (t.time > double(te.time)) {
            r.reason = "t = " + got.str() + " s is later than the contact";
        } else if (t.time < double(te.time - te.tolerance)) {
            r.reason = "t = " + got.str() + " s is too early";
        } else {
            r.pass = true;
        }
        rows.push_back(r);
    }
    for (std::size_t k = 0; k < ex.rest.size(); ++k) {
        const engine::RestExpectation& re = ex.rest[k];
        const RestTracker& t = rests[k];
        std::string what = re.name + " at rest at " + frameText(re.frames) + ":";
        if (re.max_displacement)
            what += " moves <= " + formatDouble(double(*re.max_displacement)) + " m";
        if (re.max_speed) what += " speed <= " + formatDouble(double(*re.max_speed)) + " m/s";
        CheckRow r{what, true, ""};
        if (re.frames.last >= frames) {
            r.pass = false;
            r.reason = "the run has only " + std::to_string(frames) + " frames";
        } else {
            if (re.max_displacement && t.max_displacement > double(*re.max_displacement)) {
                r.pass = false;
                r.reason = "moved " + formatDouble(t.max_displacement) + " m by frame " +
                           std::to_string(t.displacement_frame);
            }
            if (re.max_speed && t.max_speed > double(*re.max_speed)) {
                r.pass = false;
                r.reason += (r.reason.empty() ? "" : "; ") + std::string("speed ") +
                            formatDouble(t.max_speed) + " m/s at frame " +
                            std::to_string(t.speed_frame);
            }
        }
        rows.push_back(r);
    }
    for (std::size_t k = 0; k < ex.pause_dumps.size(); ++k) {
        const int f = ex.pause_dumps[k];
        const std::string problem = f >= frames
                                        ? "the run has only " + std::to_string(frames) + " frames"
                                        : verifyPauseDump(dump_dir, f, scene);
        rows.push_back({"pause dump at frame " + std::to_string(f), problem.empty(), problem});
    }
    for (std::size_t k = 0; k < ex.pairs.size(); ++k) {
        const engine::PairExpectation& p = ex.pairs[k];
        const PairTracker& t = pair_state[k];
        std::string what;
        if (p.colliding) what += *p.colliding ? "colliding" : "not colliding";
        if (p.flagged)
            what +=
                std::string(what.empty() ? "" : ", ") + (*p.flagged ? "flagged" : "not flagged");
        CheckRow r{"pair " + p.a_name + " / " + p.b_name + " " + what + " at " +
                       (p.every ? "every " : "some ") + frameText(p.frames),
                   false, ""};
        if (t.frames_seen != p.frames.last - p.frames.first + 1) {
            r.reason = "the run has only " + std::to_string(frames) + " frames";
        } else if (p.every) {
            r.pass = t.every_held;
            if (!r.pass) r.reason = "does not hold at frame " + std::to_string(t.first_violation);
        } else {
            r.pass = t.any_held;
            if (!r.pass) r.reason = "holds at no frame of the range";
        }
        rows.push_back(r);
    }
    for (std::size_t k = 0; k < ex.colors.size(); ++k) {
        const engine::ColorExpectation& c = ex.colors[k];
        std::string what;
        for (engine::BodyState s : c.present) {
            if (!what.empty()) what += ' ';
            what += colorName(s);
        }
        if (!c.absent.empty()) {
            what += what.empty() ? "no" : ", no";
            for (engine::BodyState s : c.absent) {
                what += ' ';
                what += colorName(s);
            }
        }
        CheckRow r{"colours " + what + " at frame " + std::to_string(c.frame), true, ""};
        if (c.frame >= frames) {
            r.pass = false;
            r.reason = "the run has only " + std::to_string(frames) + " frames";
        } else {
            const std::array<long, 3>& counts = color_counts[k];
            for (engine::BodyState s : c.present) {
                if (counts[std::size_t(s)] < c.min_pixels) {
                    r.pass = false;
                    r.reason += (r.reason.empty() ? "" : "; ") + colorName(s) + ": " +
                                std::to_string(counts[std::size_t(s)]) + " pixels, need " +
                                std::to_string(c.min_pixels);
                }
            }
            for (engine::BodyState s : c.absent) {
                if (counts[std::size_t(s)] >= c.min_pixels) {
                    r.pass = false;
                    r.reason += (r.reason.empty() ? "" : "; ") + colorName(s) + ": " +
                                std::to_string(counts[std::size_t(s)]) + " pixels, must be < " +
                                std::to_string(c.min_pixels);
                }
            }
        }
        rows.push_back(r);
    }
    // The scene loader rejects an `expect:` that states nothing; an Expectations built in code
    // may still be empty, and checking nothing is no pass.
    if (rows.empty()) rows.push_back({"expect", false, "states no expectation"});
    return rows;
}

int runCheck(const CheckOptions& options, std::ostream& out, std::ostream& err) {
    if (options.scenes.empty()) {
        err << "check: no scene given\n";
        return kExitBadInput;
    }
    if (options.frames && *options.frames < 1) {
        err << "--frames: must be >= 1\n";
        return kExitBadInput;
    }
    // Every scene is loaded before any runs: bad input stops the whole check.
    std::vector<engine::Scene> scenes;
    bool bad = false;
    for (const fs::path& file : options.scenes) {
        try {
            scenes.push_back(engine::loadScene(file));
        } catch (const engine::SceneError& e) {
            err << e.what() << "\n";
            bad = true;
        }
    }
    if (bad) return kExitBadInput;

    fs::path dump_root;
    bool remove_dumps = false;
    std::error_code ec;
    if (options.out_dir) {
        dump_root = *options.out_dir;
    } else {
        dump_root = fs::temp_directory_path(ec) / ("cdlab_check_" + std::to_string(::getpid()));
        remove_dumps = true;
    }

    struct Line {
        std::string scene;
        CheckRow row;
    };
    std::vector<Line> lines;
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const engine::Scene& scene = scenes[i];
        const std::string label = options.scenes[i].string();
        const int frames = options.frames.value_or(scene.expect.frames.value_or(scene.frames));
        try {
            const fs::path dir = dump_root / (std::to_string(i) + "_" + scene.name);
            if (!scene.expect.pause_dumps.empty()) {
                fs::create_directories(dir, ec);
                if (ec) throw render::RenderError("cannot create " + dir.string());
            }
            for (CheckRow& r : checkScene(scene, frames, dir)) {
                lines.push_back({label, std::move(r)});
            }
        } catch (const std::exception& e) {
            lines.push_back({label, {"run", false, std::string("could not run: ") + e.what()}});
        }
    }
    if (remove_dumps) fs::remove_all(dump_root, ec);

    std::size_t scene_w = 5, what_w = 11;
    for (const Line& l : lines) {
        scene_w = std::max(scene_w, l.scene.size());
        what_w = std::max(what_w, l.row.expectation.size());
    }
    auto pad = [](const std::string& s, std::size_t w) {
        return s + std::string(w > s.size() ? w - s.size() : 0, ' ');
    };
    int failed = 0;
    out << pad("scene", scene_w) << "  " << pad("expectation", what_w) << "  result  reason\n";
    for (const Line& l : lines) {
        failed += l.row.pass ? 0 : 1;
        out << pad(l.scene, scene_w) << "  " << pad(l.row.expectation, what_w) << "  "
            << (l.row.pass ? "pass" : "FAIL    " + l.row.reason) << "\n";
    }
    out << scenes.size() << " scene" << (scenes.size() == 1 ? "" : "s") << ", " << lines.size()
        << " expectations, " << failed << " failed\n";
    return failed == 0 ? kExitOk : kExitFailure;
}

Command addCheckCommand(CLI::App& cli) {
    struct Flags {
        CheckOptions check;
        std::vector<std::string> scenes;
        int frames = 0;
        std::string out;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd =
        cli.add_subcommand("check",
                           "run scenes headless and grade them against their 'expect:' sections: a "
                           "pass/fail table, exit 0 all pass, 1 any failure, 2 bad input");
    cmd->add_option("scenes", f->scenes, "scene files (YAML)")->required();
    cmd->add_option("--frames", f->frames,
                    "frames to run (overrides expect.frames and the scene)");
    cmd->add_option("--out", f->out,
                    "keep pause dumps in DIR (default: a temporary folder, removed)");
    return {cmd, [cmd, f]() {
                for (const std::string& sc : f->scenes) f->check.scenes.emplace_back(sc);
                if (cmd->count("--frames") > 0) f->check.frames = f->frames;
                if (!f->out.empty()) f->check.out_dir = f->out;
                return runCheck(f->check, std::cout, std::cerr);
            }};
}

}  // namespace app

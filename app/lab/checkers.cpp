// app/lab/checkers.cpp -- the checkers that observe frames (bodies, motion, rest, pause dumps, pair
// states, colours), the run they share, and makeCheckers (checkers.h); the per-step checkers are
// checkers_step.cpp.
#include "checkers.h"
#include "checkers_step.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "broadphase_check.h"
#include "collision/broadphase/broad_phase.h"
#include "output_files.h"
#include "pause_dump.h"
#include "engine/volume_overlaps.h"
#include "engine/world_draw.h"
#include "render/image.h"

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

// `pairs` in the world's pair order: a binary search when that is sorted, else a scan.
bool hasPair(std::span<const collision::ProxyPair> pairs, collision::PairOrder order,
             engine::BodyId a, engine::BodyId b) {
    const collision::ProxyPair key{std::min(a, b), std::max(a, b)};
    if (order == collision::PairOrder::Sorted) {
        return std::binary_search(pairs.begin(), pairs.end(), key);
    }
    return std::find(pairs.begin(), pairs.end(), key) != pairs.end();
}

// Pixels of each state colour in an image, indexed by BodyState.
std::array<long, 3> countStateColors(const render::Image& image) {
    std::array<std::array<int, 3>, 3> rgb{};
    for (int s = 0; s < 3; ++s) {
        const collision::Color c = engine::stateColor(static_cast<engine::BodyState>(s));
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

// ---- at least N bodies ----
class BodyCountChecker final : public Checker {
public:
    explicit BodyCountChecker(int min_bodies) : min_(min_bodies) {}
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        const std::size_t n = run.world.bodies().size();
        CheckRow r{"at least " + std::to_string(min_) + " bodies", n >= std::size_t(min_), ""};
        if (!r.pass) r.reason = "the scene has " + std::to_string(n) + " bodies";
        rows.push_back(r);
    }

private:
    int min_;
};

// ---- at least N bodies both moving and rotating, at any frame ----
class MotionChecker final : public Checker {
public:
    MotionChecker(int min_count, const engine::World& world) : min_(min_count) {
        for (const engine::Body& b : world.bodies()) {
            start_position_.push_back(b.position);
            start_orientation_.push_back(b.orientation);
        }
        max_displacement_.assign(start_position_.size(), 0.0);
        max_rotation_.assign(start_position_.size(), 0.0);
    }
    void observeFrame(CheckRun& run, int) override {
        for (std::size_t i = 0; i < start_position_.size(); ++i) {
            const engine::Body& b = run.world.bodies()[i];
            max_displacement_[i] =
                std::max(max_displacement_[i], double((b.position - start_position_[i]).norm()));
            max_rotation_[i] = std::max(
                max_rotation_[i], double(b.orientation.angularDistance(start_orientation_[i])));
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        const collision::Aabb& bounds = run.scene.world.bounds;
        const double diagonal = double((bounds.max - bounds.min).norm());
        const std::size_t n = start_position_.size();
        int count = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (max_displacement_[i] > kMinDisplacementFraction * diagonal &&
                max_rotation_[i] > kMinRotationRad) {
                ++count;
            }
        }
        CheckRow r{"at least " + std::to_string(min_) + " bodies moving and rotating",
                   count >= min_, ""};
        if (!r.pass) {
            r.reason = std::to_string(count) + " of " + std::to_string(n) +
                       " bodies both moved and rotated (> 1 degree) in " +
                       std::to_string(run.frames) + " frames";
        }
        rows.push_back(r);
    }

private:
    int min_;
    std::vector<engine::Vec3> start_position_;
    std::vector<engine::Quat> start_orientation_;
    std::vector<double> max_displacement_;
    std::vector<double> max_rotation_;
};

// ---- a body at rest over a range of frames ----
class RestChecker final : public Checker {
public:
    explicit RestChecker(const std::vector<engine::RestExpectation>& expect)
        : expect_(expect), rests_(expect.size()) {}
    void observeFrame(CheckRun& run, int frame) override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::RestExpectation& r = expect_[k];
            if (frame < r.frames.first || frame > r.frames.last) continue;
            const engine::Body& b = run.world.bodies()[r.body];
            RestTracker& t = rests_[k];
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
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::RestExpectation& re = expect_[k];
            const RestTracker& t = rests_[k];
            std::string what = re.name + " at rest at " + frameText(re.frames) + ":";
            if (re.max_displacement) {
                what += " moves <= " + formatDouble(double(*re.max_displacement)) + " m";
            }
            if (re.max_speed) what += " speed <= " + formatDouble(double(*re.max_speed)) + " m/s";
            CheckRow r{what, true, ""};
            if (const int unshown = run.firstUnshown(re.frames); unshown >= 0) {
                r.pass = false;
                r.reason = run.unshownReason(unshown);
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
    }

private:
    const std::vector<engine::RestExpectation>& expect_;
    std::vector<RestTracker> rests_;
};

// ---- a mesh body's own intersecting triangle pairs over a range of frames ----
class SelfCollisionChecker final : public Checker {
public:
    explicit SelfCollisionChecker(const std::vector<engine::SelfCollisionExpectation>& expect)
        : expect_(expect), failures_(expect.size()) {}
    void observeFrame(CheckRun& run, int frame) override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::SelfCollisionExpectation& s = expect_[k];
            if (frame < s.frames.first || frame > s.frames.last || !failures_[k].empty()) continue;
            const auto n = static_cast<int>(run.world.selfPairs(s.body).size());
            if ((s.min_pairs && n < *s.min_pairs) || (s.max_pairs && n > *s.max_pairs)) {
                failures_[k] = std::to_string(n) + " pairs at frame " + std::to_string(frame);
            }
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::SelfCollisionExpectation& s = expect_[k];
            std::string what =
                s.name + " self-intersecting triangle pairs at " + frameText(s.frames) + ":";
            if (s.min_pairs) what += " >= " + std::to_string(*s.min_pairs);
            if (s.max_pairs) what += " <= " + std::to_string(*s.max_pairs);
            CheckRow r{what, failures_[k].empty(), failures_[k]};
            if (const int unshown = run.firstUnshown(s.frames); unshown >= 0) {
                r.pass = false;
                r.reason = run.unshownReason(unshown);
            }
            rows.push_back(r);
        }
    }

private:
    const std::vector<engine::SelfCollisionExpectation>& expect_;
    std::vector<std::string> failures_;  // the first frame outside the bounds, per expectation
};

// ---- pause dumps: written at their frames as `cdlab run --pause-at` writes them, then read
// back; in a run through events, written where the track's `dump: true` entries are, as `cdlab
// run --events` writes them (the current view, paused), and a listed frame no entry dumps fails
// ----
class PauseDumpChecker final : public Checker {
public:
    explicit PauseDumpChecker(const std::vector<int>& frames) : frames_(frames) {}
    void observeEvent(CheckRun& run, int frame, const engine::DemoCommands& commands) override {
        if (!commands.dump) return;
        // run_scene.cpp's dumpFrame: the session's view and camera, the HUD of a paused frame.
        const DemoSession& session = *run.session;
        render::FrameOptions options = session.frameOptions();
        options.hud_text = session.hudText(true, false);
        const std::string stem = "pause_" + std::to_string(frame);
        render::writePng(run.dump_dir / (stem + ".png"),
                         run.renderer().render(run.world, session.camera(), options));
        writeTextAtomically(run.dump_dir / (stem + ".json"),
                            pauseDumpJson(run.world, frame, options.draw));
        dumped_.push_back(frame);
    }
    void observeFrame(CheckRun& run, int frame) override {
        if (run.session) return;  // dumps come from the track's entries
        for (const int f : frames_) {
            if (f != frame) continue;
            // The same dump `cdlab run --pause-at` writes: its picture, plus the JSON.
            render::FrameOptions options;
            options.draw = pauseDrawSettings(engine::drawSettingsFor(run.scene.draw, run.world),
                                             run.scene.draw.volumes_given);
            options.hud_text = "PAUSED  " + render::hudLine(run.world, frame, false);
            const std::string stem = "pause_" + std::to_string(frame);
            render::writePng(run.dump_dir / (stem + ".png"),
                             run.renderer().render(run.world, run.scene.camera, options));
            writeTextAtomically(run.dump_dir / (stem + ".json"),
                                pauseDumpJson(run.world, frame, options.draw));
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (const int f : frames_) {
            std::string problem;
            if (const int unshown = run.firstUnshown({f, f}); unshown >= 0) {
                problem = run.unshownReason(unshown);
            } else if (run.session &&
                       std::find(dumped_.begin(), dumped_.end(), f) == dumped_.end()) {
                problem = "no entry of the events track dumps frame " + std::to_string(f) +
                          " (its dumps: " + dumpList() + ")";
            } else {
                problem = verifyPauseDump(run.dump_dir, f, run.scene);
            }
            rows.push_back({"pause dump at frame " + std::to_string(f), problem.empty(), problem});
        }
    }

private:
    std::string dumpList() const {
        std::string list;
        for (const int f : dumped_) list += (list.empty() ? "" : ", ") + std::to_string(f);
        return list.empty() ? "none" : "frames " + list;
    }

    const std::vector<int>& frames_;
    std::vector<int> dumped_;  // frames the track's entries dumped, in the order they did
};

// ---- a pair flagged / colliding at every or some frame of a range ----
class PairChecker final : public Checker {
public:
    explicit PairChecker(const std::vector<engine::PairExpectation>& expect)
        : expect_(expect), state_(expect.size()) {}
    void observeFrame(CheckRun& run, int frame) override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::PairExpectation& p = expect_[k];
            if (frame < p.frames.first || frame > p.frames.last) continue;
            const collision::PairOrder order = run.world.settings().pair_order;
            const bool flagged = hasPair(run.world.flaggedPairs(), order, p.a, p.b);
            const bool colliding = hasPair(run.world.collidingPairs(), order, p.a, p.b);
            const bool holds = (!p.colliding || *p.colliding == colliding) &&
                               (!p.flagged || *p.flagged == flagged);
            PairTracker& t = state_[k];
            t.any_held = t.any_held || holds;
            if (!holds && t.every_held) {
                t.every_held = false;
                t.first_violation = frame;
            }
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::PairExpectation& p = expect_[k];
            const PairTracker& t = state_[k];
            std::string what;
            if (p.colliding) what += *p.colliding ? "colliding" : "not colliding";
            if (p.flagged) {
                what += std::string(what.empty() ? "" : ", ") +
                        (*p.flagged ? "flagged" : "not flagged");
            }
            CheckRow r{"pair " + p.a_name + " / " + p.b_name + " " + what + " at " +
                           (p.every ? "every " : "some ") + frameText(p.frames),
                       false, ""};
            if (const int unshown = run.firstUnshown(p.frames); unshown >= 0) {
                r.reason = run.unshownReason(unshown);
            } else if (p.every) {
                r.pass = t.every_held;
                if (!r.pass) {
                    r.reason = "does not hold at frame " + std::to_string(t.first_violation);
                }
            } else {
                r.pass = t.any_held;
                if (!r.pass) r.reason = "holds at no frame of the range";
            }
            rows.push_back(r);
        }
    }

private:
    const std::vector<engine::PairExpectation>& expect_;
    std::vector<PairTracker> state_;
};

// ---- state colours present in or absent from a rendered frame ----
class ColorChecker final : public Checker {
public:
    explicit ColorChecker(const std::vector<engine::ColorExpectation>& expect)
        : expect_(expect), counts_(expect.size()) {}
    void observeFrame(CheckRun& run, int frame) override {
        if (run.session) return;  // refused in report()
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            if (expect_[k].frame != frame) continue;
            // No HUD: its legend shows every colour whatever the state.
            render::FrameOptions options;
            options.draw = engine::drawSettingsFor(run.scene.draw, run.world);  // as cdlab run
            options.draw.hud = false;
            if (!expect_[k].volume.empty()) engine::drawOnlyVolume(options.draw, expect_[k].volume);
            counts_[k] =
                countStateColors(run.renderer().render(run.world, run.scene.camera, options));
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::ColorExpectation& c = expect_[k];
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
            std::string name = "colours " + what + " at frame " + std::to_string(c.frame);
            if (!c.volume.empty()) {
                name += " (";
                name += c.volume;
                name += " only)";
            }
            CheckRow r{name, true, ""};
            if (run.session) {
                // The loader refuses this (engine::requireGradableThroughEvents); an
                // Expectations made in code gets a failing row instead of a count of the view.
                r.pass = false;
                r.reason = "not graded in a run through an events track (its picture is the "
                           "view the track sets)";
            } else if (c.frame >= run.frames) {
                r.pass = false;
                r.reason = "the run has only " + std::to_string(run.frames) + " frames";
            } else {
                const std::array<long, 3>& counts = counts_[k];
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
                                    std::to_string(counts[std::size_t(s)]) +
                                    " pixels, must be < " + std::to_string(c.min_pixels);
                    }
                }
            }
            rows.push_back(r);
        }
    }

private:
    const std::vector<engine::ColorExpectation>& expect_;
    std::vector<std::array<long, 3>> counts_;
};

}  // namespace

void CheckRun::markShown(int frame) {
    if (frame < 0 || frame >= frames) return;
    if (shown_.empty()) shown_.assign(std::size_t(frames), 0);
    shown_[std::size_t(frame)] = 1;
}

int CheckRun::firstUnshown(const engine::FrameRange& range) const {
    if (session == nullptr) return range.last >= frames ? std::max(range.first, frames) : -1;
    for (int f = range.first; f <= range.last; ++f) {
        if (f >= frames || shown_.empty() || !shown_[std::size_t(f)]) return f;
    }
    return -1;
}

std::string CheckRun::unshownReason(int frame) const {
    if (session == nullptr || frame >= frames) {
        return "the run has only " + std::to_string(frames) + " frames";
    }
    return "frame " + std::to_string(frame) + " is never reached through the events";
}

render::Renderer& CheckRun::renderer() {
    if (!renderer_) {
        renderer_ = std::make_unique<render::Renderer>(scene.output.width, scene.output.height);
    }
    return *renderer_;
}

std::vector<std::unique_ptr<Checker>> makeCheckers(const engine::Scene& scene,
                                                   const engine::World& world) {
    const engine::Expectations& ex = scene.expect;
    std::vector<std::unique_ptr<Checker>> out;
    if (ex.min_bodies) out.push_back(std::make_unique<BodyCountChecker>(*ex.min_bodies));
    if (ex.min_moving_rotating) {
        out.push_back(std::make_unique<MotionChecker>(*ex.min_moving_rotating, world));
    }
    if (!ex.broad_phases.empty()) {
        out.push_back(makeBroadPhaseChecker(ex.broad_phases));
    }
    if (!ex.broad_phases_in_use.empty()) {
        out.push_back(makeBroadPhaseInUseChecker(ex.broad_phases_in_use));
    }
    if (ex.energy_drift_max || ex.energy_rise_max) {
        out.push_back(makeEnergyChecker(ex, world));
    }
    if (!ex.tunnelling.empty()) {
        out.push_back(makeTunnelChecker(ex.tunnelling, world));
    }
    if (!ex.toi.empty()) out.push_back(makeToiChecker(ex.toi));
    if (!ex.rest.empty()) out.push_back(std::make_unique<RestChecker>(ex.rest));
    if (!ex.self_collision.empty()) {
        out.push_back(std::make_unique<SelfCollisionChecker>(ex.self_collision));
    }
    if (!ex.pause_dumps.empty()) {
        out.push_back(std::make_unique<PauseDumpChecker>(ex.pause_dumps));
    }
    if (!ex.pairs.empty()) out.push_back(std::make_unique<PairChecker>(ex.pairs));
    if (!ex.colors.empty()) out.push_back(std::make_unique<ColorChecker>(ex.colors));
    return out;
}

}  // namespace app

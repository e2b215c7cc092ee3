// app/checkers.cpp -- one Checker per kind of expectation (checkers.h). Broad-phase agreement,
// energy, tunnelling and times of impact are observed on every step; motion, rest, pair states,
// colours and pause dumps on every frame they name.
#include "checkers.h"

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

// ---- broad phases equal to their references on every step ----
class BroadPhaseAgreementChecker final : public Checker {
public:
    explicit BroadPhaseAgreementChecker(const std::vector<std::string>& names) {
        for (const std::string& name : names) {
            const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
            ExtraBroadPhase e;
            e.name = name;
            e.phase = entry->create();
            e.reference = references_.size();
            for (std::size_t r = 0; r < references_.size(); ++r) {
                if (references_[r].name == entry->reference) e.reference = r;
            }
            if (e.reference == references_.size()) {
                references_.push_back({std::string(entry->reference),
                                       collision::findBroadPhase(entry->reference)->create(),
                                       {},
                                       0});
            }
            extra_.push_back(std::move(e));
        }
    }
    void observeStep(CheckRun& run, int frame, std::optional<double>) override {
        const engine::World& world = run.world;
        collision::BroadPhaseCounters ignored;
        for (Reference& r : references_) {
            feed(*r.phase, r.inserted, world.volumes());
            r.phase->findPairs(r.pairs, ignored);
        }
        for (ExtraBroadPhase& e : extra_) {
            if (!e.first_mismatch.empty()) continue;  // report the first mismatch only
            feed(*e.phase, e.inserted, world.volumes());
            e.phase->findPairs(e.got, ignored);
            std::string report =
                describePairMismatch(e.name, references_[e.reference].name, e.got,
                                     references_[e.reference].pairs, world.bodies());
            if (report.empty()) continue;
            std::replace(report.begin(), report.end(), '\n', ';');
            e.first_mismatch = "differs at frame " + std::to_string(frame) + ", step " +
                               std::to_string(world.stepCount()) + ": " + report;
        }
    }
    void report(const CheckRun&, std::vector<CheckRow>& rows) const override {
        for (const ExtraBroadPhase& e : extra_) {
            rows.push_back({"broad phase " + e.name + " equals " + references_[e.reference].name +
                                " every step",
                            e.first_mismatch.empty(), e.first_mismatch});
        }
    }

private:
    std::vector<Reference> references_;
    std::vector<ExtraBroadPhase> extra_;
};

// ---- energy drift and rise, relative to the initial energy, on every step ----
class EnergyChecker final : public Checker {
public:
    EnergyChecker(const engine::Expectations& ex, const engine::World& world)
        : drift_max_(ex.energy_drift_max), rise_max_(ex.energy_rise_max),
          energy0_(totalEnergy(world)) {}
    void observeStep(CheckRun& run, int frame, std::optional<double>) override {
        const double change = (totalEnergy(run.world) - energy0_) /
                              std::max(std::abs(energy0_), kMinReferenceEnergy);
        if (std::abs(change) > max_drift_) {
            max_drift_ = std::abs(change);
            max_drift_frame_ = frame;
        }
        if (change > max_rise_) {
            max_rise_ = change;
            max_rise_frame_ = frame;
        }
    }
    void report(const CheckRun&, std::vector<CheckRow>& rows) const override {
        if (drift_max_) {
            CheckRow r{"energy drift <= " + formatDouble(double(*drift_max_)),
                       max_drift_ <= double(*drift_max_), ""};
            if (!r.pass) {
                r.reason = "relative drift " + formatDouble(max_drift_) + " at frame " +
                           std::to_string(max_drift_frame_) + " (E0 = " + formatDouble(energy0_) +
                           " J)";
            }
            rows.push_back(r);
        }
        if (rise_max_) {
            CheckRow r{"energy rise <= " + formatDouble(double(*rise_max_)),
                       max_rise_ <= double(*rise_max_), ""};
            if (!r.pass) {
                r.reason = "energy rose by " + formatDouble(max_rise_) + " of E0 at frame " +
                           std::to_string(max_rise_frame_) + " (E0 = " + formatDouble(energy0_) +
                           " J)";
            }
            rows.push_back(r);
        }
    }

private:
    std::optional<engine::Real> drift_max_;
    std::optional<engine::Real> rise_max_;
    double energy0_;
    double max_drift_ = 0;
    int max_drift_frame_ = 0;
    double max_rise_ = 0;
    int max_rise_frame_ = 0;
};

// ---- a passes (or never passes) through b's box, checked on every step ----
class TunnelChecker final : public Checker {
public:
    TunnelChecker(const std::vector<engine::TunnelExpectation>& expect,
                  const engine::World& world)
        : expect_(expect), tunnels_(expect.size()) {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::TunnelExpectation& t = expect_[k];
            const engine::Vec3 c = localCentre(world, t.a, t.b);
            const engine::Vec3 h = world.volumes()[t.b].obb.half_extents;
            double best = -1;
            for (int axis = 0; axis < 3; ++axis) {
                const double out = std::abs(double(c[axis])) - double(h[axis]);
                const double relative = out / std::max(double(h[axis]), 1e-300);
                if (out > 0 && relative > best) {
                    best = relative;
                    tunnels_[k].axis = axis;
                    tunnels_[k].side = c[axis] >= 0 ? 1.0 : -1.0;
                    tunnels_[k].starts_outside = true;
                }
            }
        }
    }
    void observeStep(CheckRun& run, int frame, std::optional<double>) override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            TunnelTracker& t = tunnels_[k];
            if (!t.starts_outside || t.passed) continue;
            const engine::TunnelExpectation& te = expect_[k];
            const double c = localCentre(run.world, te.a, te.b)[t.axis];
            if (t.side * c < -double(run.world.volumes()[te.b].obb.half_extents[t.axis])) {
                t.passed = true;
                t.passed_frame = frame;
            }
        }
    }
    void report(const CheckRun&, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::TunnelExpectation& te = expect_[k];
            const TunnelTracker& t = tunnels_[k];
            CheckRow r{te.a_name + (te.passes ? " passes through " : " never passes through ") +
                           te.b_name,
                       false, ""};
            if (!t.starts_outside) {
                r.reason = te.a_name + "'s centre starts inside " + te.b_name + "'s box";
            } else if (te.passes) {
                r.pass = t.passed;
                if (!r.pass) r.reason = "it never got to the other side";
            } else {
                r.pass = !t.passed;
                if (!r.pass) {
                    r.reason = "on the other side at frame " + std::to_string(t.passed_frame);
                }
            }
            rows.push_back(r);
        }
    }

private:
    const std::vector<engine::TunnelExpectation>& expect_;
    std::vector<TunnelTracker> tunnels_;
};

// ---- the first time of impact of a pair, from the CCD stage's events ----
class ToiChecker final : public Checker {
public:
    explicit ToiChecker(const std::vector<engine::ToiExpectation>& expect)
        : expect_(expect), tois_(expect.size()) {}
    void observeStep(CheckRun& run, int, std::optional<double> step_start) override {
        if (!step_start) return;
        const double dt = double(run.world.settings().time_step);
        for (const engine::ToiEvent& e : run.world.toiEvents()) {
            for (std::size_t k = 0; k < expect_.size(); ++k) {
                const engine::ToiExpectation& te = expect_[k];
                if (tois_[k].seen || std::min(te.a, te.b) != std::min(e.a, e.b) ||
                    std::max(te.a, te.b) != std::max(e.a, e.b)) {
                    continue;
                }
                tois_[k] = {true, *step_start + double(e.t) * dt, e.failed};
            }
        }
    }
    void report(const CheckRun&, std::vector<CheckRow>& rows) const override {
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            const engine::ToiExpectation& te = expect_[k];
            const ToiTracker& t = tois_[k];
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
    }

private:
    const std::vector<engine::ToiExpectation>& expect_;
    std::vector<ToiTracker> tois_;
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
            if (re.frames.last >= run.frames) {
                r.pass = false;
                r.reason = "the run has only " + std::to_string(run.frames) + " frames";
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

// ---- pause dumps: written at their frames as `cdlab run --pause-at` writes them, then read
// back ----
class PauseDumpChecker final : public Checker {
public:
    explicit PauseDumpChecker(const std::vector<int>& frames) : frames_(frames) {}
    void observeFrame(CheckRun& run, int frame) override {
        for (const int f : frames_) {
            if (f != frame) continue;
            // The same dump `cdlab run --pause-at` writes: every volume drawn, plus the JSON.
            render::FrameOptions options;
            options.draw = run.scene.draw;
            options.draw.sphere = options.draw.aabb = options.draw.obb = true;
            options.hud_text = "PAUSED  " + render::hudLine(run.world, frame, false);
            const std::string stem = "pause_" + std::to_string(frame);
            render::writePng(run.dump_dir / (stem + ".png"),
                             run.renderer().render(run.world, run.scene.camera, options));
            writeTextAtomically(run.dump_dir / (stem + ".json"), pauseDumpJson(run.world, frame));
        }
    }
    void report(const CheckRun& run, std::vector<CheckRow>& rows) const override {
        for (const int f : frames_) {
            const std::string problem =
                f >= run.frames ? "the run has only " + std::to_string(run.frames) + " frames"
                                : verifyPauseDump(run.dump_dir, f, run.scene);
            rows.push_back({"pause dump at frame " + std::to_string(f), problem.empty(), problem});
        }
    }

private:
    const std::vector<int>& frames_;
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
            const bool flagged = hasPair(run.world.flaggedPairs(), p.a, p.b);
            const bool colliding = hasPair(run.world.collidingPairs(), p.a, p.b);
            const bool holds = (!p.colliding || *p.colliding == colliding) &&
                               (!p.flagged || *p.flagged == flagged);
            PairTracker& t = state_[k];
            ++t.frames_seen;
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
            if (t.frames_seen != p.frames.last - p.frames.first + 1) {
                r.reason = "the run has only " + std::to_string(run.frames) + " frames";
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
        for (std::size_t k = 0; k < expect_.size(); ++k) {
            if (expect_[k].frame != frame) continue;
            // No HUD: its legend shows every colour whatever the state.
            render::FrameOptions options;
            options.draw = run.scene.draw;
            options.draw.hud = false;
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
            CheckRow r{"colours " + what + " at frame " + std::to_string(c.frame), true, ""};
            if (c.frame >= run.frames) {
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
        out.push_back(std::make_unique<BroadPhaseAgreementChecker>(ex.broad_phases));
    }
    if (ex.energy_drift_max || ex.energy_rise_max) {
        out.push_back(std::make_unique<EnergyChecker>(ex, world));
    }
    if (!ex.tunnelling.empty()) {
        out.push_back(std::make_unique<TunnelChecker>(ex.tunnelling, world));
    }
    if (!ex.toi.empty()) out.push_back(std::make_unique<ToiChecker>(ex.toi));
    if (!ex.rest.empty()) out.push_back(std::make_unique<RestChecker>(ex.rest));
    if (!ex.pause_dumps.empty()) {
        out.push_back(std::make_unique<PauseDumpChecker>(ex.pause_dumps));
    }
    if (!ex.pairs.empty()) out.push_back(std::make_unique<PairChecker>(ex.pairs));
    if (!ex.colors.empty()) out.push_back(std::make_unique<ColorChecker>(ex.colors));
    return out;
}

}  // namespace app

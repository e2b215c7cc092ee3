// app/lab/checkers_step.cpp -- the checkers that observe every step (checkers_step.h): broad-phase
// agreement with the reference, energy drift and rise, tunnelling, first times of impact.
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
#include "render/image.h"

namespace app {

namespace {

// Energies below this (J) count as zero when the drift is made relative.
constexpr double kMinReferenceEnergy = 1e-12;

// Kinetic plus potential energy in uniform gravity, J (potential zero at the origin).
double totalEnergy(const engine::World& world) {
    double e = 0;
    const engine::Vec3 g = world.settings().gravity;
    for (const engine::Body& b : world.bodies()) {
        e += double(b.kineticEnergy()) - double(b.mass) * double(g.dot(b.position));
    }
    return e;
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

// ---- the world's own broad phase, whichever is in use, equal to its reference ----
// Grades what the run shows: the pairs the world's broad phase flagged, after every step and
// on the state it re-detects when an events entry switches to it. The reference is fed the
// world's volumes (after a restore too: a jump back is one more move) and loses the pairs the
// world never flags (World::pairAllowed), as the world's list does.
class BroadPhaseInUseChecker final : public Checker {
public:
    explicit BroadPhaseInUseChecker(const std::vector<std::string>& names) : listed_(names) {}
    void observeStep(CheckRun& run, int frame, std::optional<double>) override {
        grade(run.world, frame);
    }
    void observeEvent(CheckRun& run, int frame, const engine::DemoCommands& commands) override {
        if (commands.broad_phase) grade(run.world, frame);
    }
    void report(const CheckRun&, std::vector<CheckRow>& rows) const override {
        for (const std::string& name : listed_) {
            const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
            CheckRow r{"broad phase " + name + " equals " + std::string(entry->reference) +
                           " on every step it is in use",
                       false, ""};
            const InUse* u = find(name);
            if (u == nullptr) {
                r.reason = "never in use (the run used: " + usedList() + ")";
            } else {
                r.pass = u->first_mismatch.empty();
                r.reason = u->first_mismatch;
            }
            rows.push_back(r);
        }
        for (const InUse& u : used_) {
            if (std::find(listed_.begin(), listed_.end(), u.name) != listed_.end()) continue;
            rows.push_back({"broad phase " + u.name + " in use is listed", false,
                            "in use from frame " + std::to_string(u.first_frame) +
                                " but not in expect.broadphases_in_use, so not graded"});
        }
    }

private:
    struct InUse {
        std::string name;
        int first_frame = 0;
        std::unique_ptr<collision::BroadPhase> reference;
        std::string reference_name;
        std::vector<collision::ProxyPair> pairs;
        std::size_t inserted = 0;
        std::string first_mismatch;  // empty while they agree
    };

    const InUse* find(const std::string& name) const {
        for (const InUse& u : used_) {
            if (u.name == name) return &u;
        }
        return nullptr;
    }
    InUse* find(const std::string& name) {
        for (InUse& u : used_) {
            if (u.name == name) return &u;
        }
        return nullptr;
    }
    std::string usedList() const {
        std::string list;
        for (const InUse& u : used_) list += (list.empty() ? "" : ", ") + u.name;
        return list;
    }
    void grade(const engine::World& world, int frame) {
        const std::string name(world.broadPhase().name());
        InUse* u = find(name);
        if (u == nullptr) {
            const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
            InUse fresh;
            fresh.name = name;
            fresh.first_frame = frame;
            fresh.reference_name = std::string(entry->reference);
            fresh.reference = collision::findBroadPhase(entry->reference)->create();
            used_.push_back(std::move(fresh));
            u = &used_.back();
        }
        if (!u->first_mismatch.empty()) return;  // report the first mismatch only
        feed(*u->reference, u->inserted, world.volumes());
        collision::BroadPhaseCounters ignored;
        u->reference->findPairs(u->pairs, ignored);
        u->pairs.erase(std::remove_if(u->pairs.begin(), u->pairs.end(),
                                      [&](const collision::ProxyPair& p) {
                                          return !world.pairAllowed(engine::BodyId(p.a),
                                                                    engine::BodyId(p.b));
                                      }),
                       u->pairs.end());
        std::string report = describePairMismatch(name, u->reference_name, world.flaggedPairs(),
                                                  u->pairs, world.bodies());
        if (report.empty()) return;
        std::replace(report.begin(), report.end(), '\n', ';');
        u->first_mismatch = "differs at frame " + std::to_string(frame) + ", step " +
                            std::to_string(world.stepCount()) + ": " + report;
    }

    std::vector<std::string> listed_;
    std::vector<InUse> used_;  // in the order the run first used them
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

}  // namespace

std::unique_ptr<Checker> makeBroadPhaseChecker(const std::vector<std::string>& names) {
    return std::make_unique<BroadPhaseAgreementChecker>(names);
}

std::unique_ptr<Checker> makeBroadPhaseInUseChecker(const std::vector<std::string>& names) {
    return std::make_unique<BroadPhaseInUseChecker>(names);
}

std::unique_ptr<Checker> makeEnergyChecker(const engine::Expectations& ex,
                                           const engine::World& world) {
    return std::make_unique<EnergyChecker>(ex, world);
}

std::unique_ptr<Checker> makeTunnelChecker(const std::vector<engine::TunnelExpectation>& expect,
                                           const engine::World& world) {
    return std::make_unique<TunnelChecker>(expect, world);
}

std::unique_ptr<Checker> makeToiChecker(const std::vector<engine::ToiExpectation>& expect) {
    return std::make_unique<ToiChecker>(expect);
}

}  // namespace app

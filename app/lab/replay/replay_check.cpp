// app/lab/replay/replay_check.cpp -- see replay_check.h.
#include "replay/replay_check.h"

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "engine/recording.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "exit_codes.h"
#include "replay/run_recorder.h"

namespace app {

namespace {

std::string vecText(const engine::Vec3& v) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "[%.17g, %.17g, %.17g]", double(v.x()), double(v.y()),
                  double(v.z()));
    return buffer;
}

std::string quatText(const engine::Quat& q) {
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, "[w %.17g, x %.17g, y %.17g, z %.17g]", double(q.w()),
                  double(q.x()), double(q.y()), double(q.z()));
    return buffer;
}

bool sameBits(const engine::Vec3& a, const engine::Vec3& b) {
    return a.x() == b.x() && a.y() == b.y() && a.z() == b.z();
}

// The first difference between a recorded frame and the simulated one, in the order a state
// is built: time, each body's position, orientation and momenta (every bit), chain clocks, then
// pairs and the hash; "" when there is none.
std::string firstDifference(const engine::RecordedFrame& rec, const engine::RecordedFrame& sim,
                            const engine::Scene& scene) {
    if (rec.state.time != sim.state.time) {
        return "the time: recorded " + std::to_string(rec.state.time) + " s, simulated " +
               std::to_string(sim.state.time) + " s";
    }
    for (std::size_t i = 0; i < rec.state.bodies.size(); ++i) {
        const engine::BodyMotion& r = rec.state.bodies[i];
        const engine::BodyMotion& s = sim.state.bodies[i];
        const std::string who = "body " + scene.bodies[i].name + "'s ";
        if (!sameBits(r.position, s.position)) {
            return who + "position: recorded " + vecText(r.position) + ", simulated " + vecText(s.position);
        }
        if (r.orientation.coeffs() != s.orientation.coeffs()) {
            return who + "orientation: recorded " + quatText(r.orientation) + ", simulated " +
                   quatText(s.orientation);
        }
        if (!sameBits(r.linear_momentum, s.linear_momentum)) {
            return who + "linear momentum: recorded " + vecText(r.linear_momentum) + ", simulated " +
                   vecText(s.linear_momentum);
        }
        if (!sameBits(r.angular_momentum, s.angular_momentum)) {
            return who + "angular momentum: recorded " + vecText(r.angular_momentum) +
                   ", simulated " + vecText(s.angular_momentum);
        }
    }
    for (std::size_t c = 0; c < rec.state.chains.size(); ++c) {
        if (rec.state.chains[c].time != sim.state.chains[c].time ||
            rec.state.chains[c].halted != sim.state.chains[c].halted) {
            return "chain " + scene.chains[c].name + "'s clock";
        }
    }
    // The pairs as sets: their order follows the broad phase under pair_order: found.
    auto sorted = [](std::vector<collision::ProxyPair> p) {
        std::sort(p.begin(), p.end());
        return p;
    };
    if (sorted(rec.flagged) != sorted(sim.flagged)) return "the flagged pairs";
    if (sorted(rec.colliding) != sorted(sim.colliding)) return "the confirmed pairs";
    if (rec.state_hash != sim.state_hash) return "the state hash alone (the overlap states)";
    return "";
}

void printSummary(const engine::Recording& r, std::ostream& out) {
    const engine::RecordingHeader& h = r.header();
    out << r.file().string() << ": cdlab recording, format version " << h.version << "\n"
        << "  scene       " << h.scene.string() << "\n";
    for (const engine::SceneOverride& o : h.overrides) {
        out << "  --set       " << o.key << "=" << o.value << "\n";
    }
    char per_body[32];
    std::snprintf(per_body, sizeof per_body, "%.1f",
                  double(r.bytes()) / (double(r.frames()) * double(h.bodies)));
    out << "  broadphase  " << h.broad_phase << " (pairs "
        << collision::pairOrderName(h.pair_order) << ")\n"
        << "  frames      " << r.frames() << " of " << h.frames << " (" << h.steps_per_frame
        << " steps of " << h.time_step << " s each)"
        << (r.ended().empty() ? "" : "; the run " + r.ended()) << "\n"
        << "  bodies      " << h.bodies << (h.chains ? ", chains " + std::to_string(h.chains) : "")
        << "\n"
        << "  size        " << r.bytes() << " bytes, " << per_body << " bytes per body per frame\n";
}

}  // namespace

int replayRecording(const ReplayOptions& options, std::ostream& out, std::ostream& err) {
    if (options.frames && *options.frames < 1) {
        err << "--frames: must be >= 1\n";
        return kExitBadInput;
    }
    if (std::error_code ec; !std::filesystem::exists(options.recording, ec)) {
        err << "recording " << options.recording.string() << ": no such file or folder\n";
        return kExitBadInput;
    }
    std::optional<engine::Recording> recording;
    engine::Scene scene;
    try {
        recording = engine::Recording::open(options.recording);
        if (!options.check && !options.dry_run) {
            printSummary(*recording, out);
            return kExitOk;
        }
        scene = loadRecordedScene(*recording, options.scene);
        if (options.dry_run) return kExitOk;
    } catch (const engine::RecordingError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    const int frames = std::min(recording->frames(), options.frames.value_or(recording->frames()));
    int frame = 0;
    try {
        engine::World world = engine::makeWorld(scene);
        for (; frame < frames; ++frame) {
            if (frame > 0) {
                for (int s = 0; s < scene.steps_per_frame; ++s) world.step();
            }
            const engine::RecordedFrame rec = recording->frame(frame);
            // The run's events may have switched the broad phase (the motion does not follow
            // it, recordRefusal): its pairs are those of the frame's own broad phase.
            if (rec.broad_phase != world.broadPhase().name()) world.setBroadPhase(rec.broad_phase);
            const engine::RecordedFrame sim = engine::recordFrame(world, frame);
            const std::string difference = firstDifference(rec, sim, scene);
            if (difference.empty()) continue;
            out << options.recording.string() << ": frame " << frame
                << " differs from the simulation (state hash recorded " << std::hex
                << rec.state_hash << ", simulated " << sim.state_hash << std::dec
                << "): first " << difference << "\n";
            if (frame > 0) out << "frames 0.." << frame - 1 << " match\n";
            return kExitCheckFailed;
        }
    } catch (const engine::RecordingError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    } catch (const std::exception& e) {
        err << "error: " << options.recording.string() << ": frame " << frame
            << ": the simulation failed: " << e.what() << "\n";
        return kExitFailure;
    }
    out << options.recording.string() << ": frames 0.." << frames - 1
        << " match the simulation bit for bit (states, pairs, state hashes)";
    if (frames < recording->frames()) out << " (of " << recording->frames() << " recorded)";
    if (!recording->ended().empty()) out << "; the recorded run " << recording->ended();
    out << "\n";
    return kExitOk;
}

}  // namespace app

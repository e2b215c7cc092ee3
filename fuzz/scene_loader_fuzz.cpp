// fuzz/scene_loader_fuzz.cpp -- libFuzzer target over the scene loader (engine/scene.h).
// Any input must either load or throw SceneError: a crash, a sanitizer report, another exception,
// a leak or a hang is a bug. Small scenes that load are also built and stepped, so that whatever
// the loader lets through (sizes, poses, velocities, gravity) must survive the pipeline without a
// NaN: a SimulationError from the step (a state no longer finite) is a finding too, since the
// loader's magnitude limits exist to refuse such scenes first. Each small scene is stepped under
// its own broad phase and under the cell-based ones (grid, hash), whose cell arithmetic meets
// extreme extents first.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "collision/visibility_oracle.h"
#include "engine/scene.h"

namespace {

// Worlds bigger than this are only loaded, not stepped: stepping is quadratic in the worst case
// and the fuzzer's time goes to inputs, not to long runs.
constexpr std::size_t kMaxSteppedBodies = 64;
constexpr int kSteps = 2;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    // An input whose first line is "#set KEY=VALUE" also applies that override, as `--set` does
    // (a comment to YAML, so the rest of the file still parses the same).
    std::vector<engine::SceneOverride> overrides;
    if (text.rfind("#set ", 0) == 0) {
        const std::string line = text.substr(5, text.find('\n') - 5);
        const std::size_t eq = line.find('=');
        if (eq != std::string::npos) overrides.push_back({line.substr(0, eq), line.substr(eq + 1)});
    }
    engine::Scene scene;
    try {
        // Mesh paths resolve like a file in scenes/, so seeds that name ../assets/*.obj load.
        scene = engine::parseScene(text, "fuzz.yaml", CDLAB_FUZZ_BASE_DIR, overrides);
    } catch (const engine::SceneError& e) {
        // Messages are "FILE:LINE:COL: path: what" (or "FILE: --set K=V: path: what"), one line.
        const std::string what = e.what();
        const bool positioned = what.rfind("fuzz.yaml:", 0) == 0;
        if (!positioned || what.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    if (scene.bodies.size() > kMaxSteppedBodies) return 0;
    for (const char* broad_phase : {"", "grid", "hash"}) {
        engine::Scene variant = scene;
        if (*broad_phase != '\0') variant.world.broad_phase = broad_phase;
        std::optional<engine::World> made;
        try {
            made.emplace(engine::makeWorld(variant));
        } catch (const collision::BroadPhaseUnavailable&) {
            // A broad phase that renders (cullide) in a process without the render module:
            // a documented, clear error, not a finding. cullide_tests covers that broad phase.
            continue;
        }
        engine::World& world = *made;
        for (int s = 0; s < kSteps; ++s) world.step();  // SimulationError escapes: a finding
        for (const engine::Body& b : world.bodies()) {
            if (!b.position.allFinite() || !b.linear_momentum.allFinite() ||
                !b.angular_momentum.allFinite() || !b.orientation.coeffs().allFinite()) {
                std::abort();
            }
        }
    }
    return 0;
}

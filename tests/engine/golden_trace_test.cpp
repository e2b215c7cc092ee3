// Golden traces: every shipped scene, run for its checked frames, must give bit-for-bit the states
// and pairs recorded in tests/data/golden_traces.txt. A change meant to keep behaviour (a
// refactor, a faster equal algorithm) keeps these; one that changes behaviour on purpose records
// new ones and says why in its commit:
//   CDLAB_UPDATE_GOLDEN=1 build/bin/engine_tests --gtest_filter='GoldenTrace.*'
// The digest covers, after every frame, World::stateHash (every body's pose and momenta, bit
// patterns) and the flagged and colliding pair lists. IEEE double arithmetic without fused
// multiply-add (plain x86-64) gives the same bits at -O1 and -O3, so the sanitizer build checks
// the same digests; the float build (CDLAB_USE_FLOAT) does not run this suite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace {

namespace fs = std::filesystem;

const fs::path kGoldenFile = fs::path(CDLAB_SOURCE_DIR) / "tests/data/golden_traces.txt";

// FNV-1a, as World::stateHash.
struct Digest {
    std::uint64_t h = 1469598103934665603ull;
    void mix(const void* data, std::size_t n) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            h ^= bytes[i];
            h *= 1099511628211ull;
        }
    }
    template <typename T>
    void mix(const T& value) {
        mix(&value, sizeof value);
    }
    void mixPairs(std::span<const collision::ProxyPair> pairs) {
        mix(pairs.size());
        for (const collision::ProxyPair& p : pairs) {
            mix(p.a);
            mix(p.b);
        }
    }
};

struct Trace {
    int frames = 0;
    std::uint64_t digest = 0;
};

Trace runScene(const fs::path& file) {
    engine::Scene scene = engine::loadScene(file);
    // A broad phase that renders (cullide) cannot be made here; its reference reports the same
    // pairs by contract (checked in cullide_tests and by the scene's expect: broadphases), so the
    // trace is the one the scene runs.
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(scene.world.broad_phase);
    if (entry != nullptr && entry->needs_render_context) {
        scene.world.broad_phase = std::string(entry->reference);
    }
    engine::World world = engine::makeWorld(scene);
    Trace t;
    t.frames = scene.expect.frames.value_or(scene.frames);
    Digest d;
    for (int frame = 0; frame < t.frames; ++frame) {
        if (frame > 0) {
            for (int s = 0; s < scene.steps_per_frame; ++s) world.step();
        }
        d.mix(world.stateHash());
        d.mixPairs(world.flaggedPairs());
        d.mixPairs(world.collidingPairs());
    }
    t.digest = d.h;
    return t;
}

std::vector<fs::path> shippedScenes() {
    std::vector<fs::path> out;
    for (const auto& entry : fs::directory_iterator(fs::path(CDLAB_SOURCE_DIR) / "scenes")) {
        if (entry.path().extension() == ".yaml") out.push_back(entry.path());
    }
    std::sort(out.begin(), out.end());
    return out;
}

// "name frames digest" per line.
std::map<std::string, Trace> readGolden() {
    std::map<std::string, Trace> out;
    std::ifstream in(kGoldenFile);
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream fields(line);
        std::string name;
        Trace t;
        fields >> name >> t.frames >> std::hex >> t.digest;
        if (fields) out[name] = t;
    }
    return out;
}

TEST(GoldenTrace, EveryShippedSceneReproducesItsRecordedTrace) {
    const bool update = std::getenv("CDLAB_UPDATE_GOLDEN") != nullptr;
    const std::map<std::string, Trace> golden = readGolden();
    std::ostringstream fresh;
    fresh << "# scene, frames run, FNV-1a digest of every frame's state hash and pair lists\n"
          << "# (tests/engine/golden_trace_test.cpp). Regenerate only for a change of behaviour.\n";
    for (const fs::path& file : shippedScenes()) {
        const std::string name = file.stem().string();
        SCOPED_TRACE(name);
        const Trace t = runScene(file);
        char digest[17];
        std::snprintf(digest, sizeof digest, "%016llx", static_cast<unsigned long long>(t.digest));
        fresh << name << ' ' << t.frames << ' ' << digest << '\n';
        if (update) continue;
        const auto it = golden.find(name);
        ASSERT_NE(it, golden.end()) << "no recorded trace for " << name << " in " << kGoldenFile
                                    << " (record with CDLAB_UPDATE_GOLDEN=1)";
        EXPECT_EQ(t.frames, it->second.frames);
        EXPECT_EQ(t.digest, it->second.digest)
            << name << ": the states or pairs differ from the recorded trace";
    }
    if (update) {
        std::ofstream(kGoldenFile) << fresh.str();
        GTEST_SKIP() << "recorded " << kGoldenFile;
    }
    // Every recorded scene still ships.
    for (const auto& [name, t] : golden) {
        EXPECT_TRUE(fs::exists(fs::path(CDLAB_SOURCE_DIR) / "scenes" / (name + ".yaml"))) << name;
    }
}

}  // namespace

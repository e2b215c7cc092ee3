// fuzz/demo_command_fuzz.cpp -- libFuzzer target over one demo command (engine/demo_commands.h),
// the text a live session takes from the network (POST /api/command) against the coursework
// scene. Any input must either read or throw SceneError with a one-line "command:LINE:COL: ..."
// message; a crash, a sanitizer report, another exception, a leak or a hang is a bug. A command
// that reads must also survive the session log: written as an event (eventsYaml) it reads back
// to the same text, or a replay would not be the session.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "engine/demo_commands.h"
#include "engine/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const engine::Scene scene = engine::loadScene(CDLAB_FUZZ_SCENE);
    const std::string text(reinterpret_cast<const char*>(data), size);
    engine::DemoCommands commands;
    try {
        commands = engine::parseDemoCommands(text, "command", scene);
    } catch (const engine::SceneError& e) {
        const std::string what = e.what();
        if (what.rfind("command:", 0) != 0 || what.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    // Frame 0 may be left by a step or a seek the track check refuses: the log only ever holds
    // commands a session applied, so a frame that keeps the entry reachable is chosen.
    const int frame = commands.step && *commands.step < 0 ? -*commands.step : 0;
    const std::vector<engine::DemoEvent> events = {{frame, commands, 0, 0}};
    const std::string log = engine::eventsYaml(events, scene);
    std::vector<engine::DemoEvent> back;
    try {
        back = engine::parseEvents(log, "log.yaml", scene);
    } catch (const engine::SceneError&) {
        std::abort();
    }
    if (back.size() != 1 || engine::eventsYaml(back, scene) != log) std::abort();
    return 0;
}

// app/lab/demo/demo_playback.cpp -- see demo_playback.h. The loop is the one of `cdlab run`
// (run_scene.cpp): entries apply when the session's frame is theirs, each once, in file order;
// a paused session moves only by an entry's step or seek.
#include "demo/demo_playback.h"

#include <stdexcept>
#include <string>

namespace app {

void playDemo(DemoSession& session, const std::vector<engine::DemoEvent>& events,
              const DemoPlaybackHooks& hooks) {
    auto shown = [&] {
        if (hooks.frame_shown) hooks.frame_shown();
    };
    shown();
    std::size_t next = 0;
    for (;;) {
        while (next < events.size() && events[next].frame == session.frame()) {
            const engine::DemoEvent& e = events[next++];
            const std::string problem = session.apply(e.commands, shown);
            if (!problem.empty()) throw std::logic_error("events: " + problem);
            if (hooks.event_applied) hooks.event_applied(e);
        }
        if (!session.playing()) return;
        if (!session.advance()) return;
        shown();
    }
}

}  // namespace app

// app/lab/serve/live_session.cpp -- see live_session.h.
// Invariants: the session thread alone owns the DemoSession and the Renderer; a command's
// answer is given only after the picture it changed was published, so a caller that fetches
// the frame after its answer sees the change; a frame is left (by playing on) only in a later
// turn of the loop than the one that applied commands to it, so the published picture of every
// frame after its commands is the one `cdlab run --events` writes as that frame's PNG.
#include "serve/live_session.h"

#include <algorithm>
#include <exception>
#include <future>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "demo/demo_session.h"
#include "engine/scene.h"
#include "output_files.h"
#include "pause_dump.h"
#include "render/image.h"
#include "render/renderer.h"

namespace app {

namespace {

using Clock = std::chrono::steady_clock;

// The session's view as the page shows it: which layers are on, the selection, the speed.
nlohmann::ordered_json viewJson(const DemoSession& session) {
    const engine::World& world = session.world();
    nlohmann::ordered_json layers = nlohmann::ordered_json::array();
    for (int i = 0; i <= int(engine::DemoLayer::Hud); ++i) {
        const auto layer = engine::DemoLayer(i);
        if (session.shows(layer)) layers.push_back(std::string(engine::demoLayerName(layer)));
    }
    nlohmann::ordered_json v;
    v["frame"] = session.frame();
    v["last_frame"] = session.lastFrame();
    v["playing"] = session.playing();
    v["speed"] = session.view().speed;
    v["broadphase"] = std::string(world.broadPhase().name());
    v["layers"] = std::move(layers);
    const auto name = [&](const std::optional<engine::BodyId>& id) {
        return id ? nlohmann::ordered_json(world.bodies()[std::size_t(*id)].name)
                  : nlohmann::ordered_json(nullptr);
    };
    v["selected"] = name(session.view().selected);
    v["follow"] = name(session.view().follow);
    v["hud"] = session.hudText(!session.playing(), false);
    nlohmann::ordered_json rects = nlohmann::ordered_json::array();
    const engine::Scene& scene = session.scene();
    for (const auto& r :
         bodyRects(world, session.camera(), scene.output.width, scene.output.height)) {
        rects.push_back(r ? nlohmann::ordered_json{r->x0, r->y0, r->x1, r->y1}
                          : nlohmann::ordered_json(nullptr));
    }
    v["rects"] = std::move(rects);
    return v;
}

}  // namespace

LiveSession::LiveSession(const engine::Scene& scene, LiveOptions options)
    : scene_(scene), options_(std::move(options)) {
    std::promise<void> started;
    std::future<void> ready = started.get_future();
    thread_ = std::thread([this, &started] { loop(started); });
    try {
        ready.get();
    } catch (...) {
        thread_.join();
        throw;
    }
}

LiveSession::~LiveSession() { stop(); }

void LiveSession::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
    writeLog();
}

LiveAnswer LiveSession::command(const std::string& text, std::chrono::milliseconds timeout) {
    LiveAnswer refused;
    Pending pending;
    try {
        pending.commands = engine::parseDemoCommands(text, "command", scene_);
    } catch (const std::exception& e) {
        refused.error = e.what();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    refused.at_frame = refused.frame = latest_ ? latest_->frame : 0;
    if (!refused.error.empty()) return refused;
    if (stopping_ || !failure_.empty()) {
        refused.error = "the session has stopped" + (failure_.empty() ? "" : ": " + failure_);
        return refused;
    }
    if (queue_.size() >= options_.max_queued) {
        refused.error = "busy: " + std::to_string(queue_.size()) +
                        " commands are waiting for the next frame; send again later";
        return refused;
    }
    pending.id = next_id_++;
    const std::uint64_t id = pending.id;
    queue_.push_back(std::move(pending));
    changed_.notify_all();
    LiveAnswer answer;
    bool got = false;
    const auto answered = [&] {
        const auto it = std::find_if(answers_.begin(), answers_.end(),
                                     [&](const auto& a) { return a.first == id; });
        if (it == answers_.end()) return false;
        answer = std::move(it->second);
        answers_.erase(it);
        got = true;
        return true;
    };
    changed_.wait_for(lock, timeout, [&] { return answered() || stopping_; });
    if (got) return answer;
    // Not applied in time: taken back if it still waits, so it never applies unanswered.
    const auto it = std::find_if(queue_.begin(), queue_.end(),
                                 [&](const Pending& p) { return p.id == id; });
    if (it != queue_.end()) {
        queue_.erase(it);
        refused.error = stopping_ ? "the session has stopped" : "the session did not answer in time";
        return refused;
    }
    // Being applied right now: its answer comes with the next picture.
    changed_.wait(lock, [&] { return answered() || stopping_; });
    if (got) return answer;
    refused.error = "the session has stopped";
    return refused;
}

std::shared_ptr<const LiveFrame> LiveSession::frame(std::optional<std::uint64_t> after,
                                                    std::chrono::milliseconds timeout) const {
    std::unique_lock<std::mutex> lock(mutex_);
    if (after) {
        changed_.wait_for(lock, timeout, [&] {
            return stopping_ || (latest_ && latest_->version > *after);
        });
    }
    return latest_;
}

std::shared_ptr<const LiveFrame> LiveSession::frameAt(std::uint64_t version) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& f : held_) {
        if (f->version == version) return f;
    }
    return nullptr;
}

std::string LiveSession::logYaml() const {
    std::string text;
    for (const std::string& line : options_.log_comment) text += "# " + line + "\n";
    std::lock_guard<std::mutex> lock(mutex_);
    if (log_.empty()) return text + "# no command yet\nevents: []\n";
    return text + engine::eventsYaml(log_, scene_);
}

std::string LiveSession::timelineJson(std::size_t from) const {
    const auto nullable = [](double ms) {
        return ms < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(ms);
    };
    constexpr std::size_t kMaxRows = 10000;
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = from; i < timeline_.size() && i < from + kMaxRows; ++i) {
        const TimelineRow& r = timeline_[i];
        rows.push_back({{"frame", r.frame},
                        {"time", r.time},
                        {"flagged", r.flagged},
                        {"colliding", r.colliding},
                        {"step_ms", r.step_ms},
                        {"render_ms", nullable(r.render_ms)},
                        {"png_ms", nullable(r.png_ms)},
                        {"state_ms", nullable(r.state_ms)}});
    }
    return rows.dump();
}

std::string LiveSession::pairHistoryJson(const std::string& a, const std::string& b) const {
    auto find = [&](const std::string& name) {
        for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
            if (scene_.bodies[i].name == name) return collision::ProxyId(i);
        }
        throw std::invalid_argument("no body named '" + name + "' in the scene");
    };
    const collision::ProxyId ia = find(a), ib = find(b);
    if (ia == ib) throw std::invalid_argument("a pair is of two bodies, not '" + a + "' twice");
    PairHistory::Ranges r;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        r = history_.of(ia, ib);
    }
    auto ranges = [](const std::vector<std::pair<int, int>>& list) {
        nlohmann::ordered_json out = nlohmann::ordered_json::array();
        for (const auto& [first, last] : list) out.push_back({first, last});
        return out;
    };
    nlohmann::ordered_json j = {{"a", a},
                                {"b", b},
                                {"frames", r.frames},
                                {"flagged", ranges(r.flagged)},
                                {"colliding", ranges(r.colliding)}};
    return j.dump();
}

std::string LiveSession::failure() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return failure_;
}

void LiveSession::writeLog() const {
    if (!options_.log_file) return;
    writeTextAtomically(*options_.log_file, logYaml());
}

void LiveSession::loop(std::promise<void>& started) {
    std::optional<DemoSession> session;
    std::optional<render::Renderer> renderer;
    try {
        if (options_.replay) {
            session.emplace(scene_, options_.structure, *options_.replay);
        } else {
            session.emplace(scene_, options_.structure);
        }
        renderer.emplace(scene_.output.width, scene_.output.height);
    } catch (...) {
        started.set_exception(std::current_exception());
        return;
    }
    double step_ms = 0;  // the world steps since the last frame reached
    int newest = -1;     // the furthest frame reached
    // Every frame's pairs the first time the simulation reaches it (a seek steps through frames
    // it does not show), or a recording's, all of them, read once.
    const auto keepPairs = [&](const engine::World& w, int frame) {
        std::lock_guard<std::mutex> lock(mutex_);
        history_.add(frame, w.flaggedPairs(), w.collidingPairs());
    };
    if (options_.replay) {
        try {
            for (int k = 0; k < options_.replay->frames(); ++k) {
                const engine::RecordedFrame f = options_.replay->frame(k);
                std::lock_guard<std::mutex> lock(mutex_);
                history_.add(k, f.flagged, f.colliding);
            }
        } catch (...) {
            started.set_exception(std::current_exception());
            return;
        }
    } else {
        keepPairs(session->world(), 0);
    }
    session->on_step = [&](const engine::World& w) {
        step_ms += 1e3 * w.lastStats().total_s;
        if (w.stepCount() % scene_.steps_per_frame == 0) {
            keepPairs(w, int(w.stepCount() / scene_.steps_per_frame));
        }
    };
    const auto reached = [&] {
        if (session->frame() > newest) {
            newest = session->frame();
            const engine::World& w = session->world();
            std::lock_guard<std::mutex> lock(mutex_);
            timeline_.push_back({newest, double(w.time()), w.flaggedPairs().size(),
                                 w.collidingPairs().size(), step_ms});
        }
        step_ms = 0;
    };
    std::uint64_t version = 0;
    const auto publish = [&] {
        auto f = std::make_shared<LiveFrame>();
        f->version = ++version;
        f->frame = session->frame();
        f->playing = session->playing();
        render::FrameOptions frame_options = session->frameOptions();
        frame_options.hud_text = session->hudText(!session->playing(), false);
        const Clock::time_point t0 = Clock::now();
        const render::Image image =
            renderer->render(session->world(), session->camera(), frame_options);
        const Clock::time_point t1 = Clock::now();
        f->png = render::pngBytes(image);
        const Clock::time_point t2 = Clock::now();
        // The pause dump with "session" as its last member, spliced into the dump's compact
        // text rather than parsed and printed again.
        nlohmann::ordered_json view = viewJson(*session);
        view["version"] = f->version;
        f->state = pauseDumpJson(session->world(), f->frame, frame_options.draw, true);
        f->state.pop_back();
        f->state += ",\"session\":" + view.dump() + "}";
        const Clock::time_point t3 = Clock::now();
        std::lock_guard<std::mutex> lock(mutex_);
        if (!timeline_.empty() && timeline_.back().frame == f->frame &&
            timeline_.back().render_ms < 0) {
            const auto ms = [](Clock::duration d) {
                return std::chrono::duration<double, std::milli>(d).count();
            };
            timeline_.back().render_ms = ms(t1 - t0);
            timeline_.back().png_ms = ms(t2 - t1);
            timeline_.back().state_ms = ms(t3 - t2);
        }
        held_.push_back(f);
        if (held_.size() > kHeldFrames) held_.pop_front();
        latest_ = std::move(f);
        changed_.notify_all();
    };
    const auto period = [&] {
        return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
            1.0 / (double(scene_.output.fps) * session->view().speed)));
    };
    const auto log = [&](int frame, const engine::DemoCommands& commands) {
        std::lock_guard<std::mutex> lock(mutex_);
        log_.push_back({frame, commands, 0, 0});
    };
    const auto dump = [&] {
        const int frame = session->frame();
        render::FrameOptions dump_options = session->frameOptions();
        dump_options.hud_text = session->hudText(true, false);
        const std::string stem = "pause_" + std::to_string(frame);
        render::writePng(*options_.dump_dir / (stem + ".png"),
                         renderer->render(session->world(), session->camera(), dump_options));
        writeTextAtomically(*options_.dump_dir / (stem + ".json"),
                            pauseDumpJson(session->world(), frame, dump_options.draw));
    };

    try {
        if (options_.paused) {
            engine::DemoCommands pause;
            pause.playing = false;
            session->apply(pause);
            log(0, pause);
        }
        reached();
        publish();
        writeLog();
    } catch (...) {
        started.set_exception(std::current_exception());
        return;
    }
    started.set_value();

    Clock::time_point next_tick = Clock::now() + period();
    std::deque<Pending> work;
    try {
        for (;;) {
            {
                std::unique_lock<std::mutex> lock(mutex_);
                const auto woken = [&] { return stopping_ || !queue_.empty(); };
                if (session->playing()) {
                    changed_.wait_until(lock, next_tick, woken);
                } else {
                    changed_.wait(lock, woken);
                }
                if (stopping_) break;
                work.swap(queue_);
            }
            if (!work.empty()) {
                std::vector<std::pair<std::uint64_t, LiveAnswer>> done;
                for (Pending& p : work) {
                    LiveAnswer a;
                    a.at_frame = session->frame();
                    std::size_t logged = 0;
                    {
                        std::lock_guard<std::mutex> lock(mutex_);
                        logged = log_.size();
                    }
                    if (logged >= engine::kMaxDemoEvents) {
                        a.error = "the session log is full (" +
                                  std::to_string(engine::kMaxDemoEvents) +
                                  " commands, the most an events track holds)";
                    } else if (p.commands.dump && !options_.dump_dir) {
                        a.error = "command.dump: this session writes no files";
                    } else {
                        a.error = session->apply(p.commands, reached);
                        if (a.error.empty()) {
                            log(a.at_frame, p.commands);
                            if (p.commands.dump) dump();
                            // A picture per command, as `run --events` draws one per event.
                            publish();
                            a.ok = true;
                        }
                    }
                    a.frame = session->frame();
                    done.emplace_back(p.id, std::move(a));
                }
                work.clear();
                writeLog();
                {
                    std::lock_guard<std::mutex> lock(mutex_);
                    for (auto& d : done) answers_.push_back(std::move(d));
                }
                changed_.notify_all();
                // The frame is left in a later turn: its picture after these commands stays
                // the one published for it.
                continue;
            }
            if (!session->playing() || Clock::now() < next_tick) continue;
            if (session->advance()) {
                reached();
            } else {
                // The last frame: the session pauses there, and says so in its log, so that a
                // replay pauses there too.
                engine::DemoCommands pause;
                pause.playing = false;
                session->apply(pause);
                log(session->frame(), pause);
                writeLog();
            }
            publish();
            next_tick += period();
            // Behind by more than a frame (a slow step or render): play on from now rather
            // than rushing to catch up.
            if (next_tick < Clock::now()) next_tick = Clock::now() + period();
        }
    } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        failure_ = "frame " + std::to_string(session->frame()) + ": " + e.what();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    changed_.notify_all();
}

}  // namespace app

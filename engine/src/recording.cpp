// engine/src/recording.cpp -- see recording.h. Layout (docs/recording.md): the magic
// "CDLABREC", a u32 version, a u32 length and the header as YAML text, then records, each a u32
// tag, a u32 length, that many bytes and the FNV-1a (64) of them: one 'FRAM' per frame and one
// 'END!' last. Numbers are little-endian, doubles their IEEE-754 bits.
#include "engine/recording.h"

#include <yaml-cpp/yaml.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>
#include <type_traits>

namespace engine {

static_assert(std::endian::native == std::endian::little,
              "recordings are written as the machine's bytes: little-endian only");

namespace {

constexpr char kMagic[8] = {'C', 'D', 'L', 'A', 'B', 'R', 'E', 'C'};
constexpr std::uint32_t kFrameTag = 0x4d415246;  // "FRAM"
constexpr std::uint32_t kEndTag = 0x21444e45;    // "END!"
// A header is a page of YAML; a frame of 10 million bodies is 1 GB. Larger is not a recording.
constexpr std::uint32_t kMaxHeaderBytes = 1u << 20;
constexpr std::uint32_t kMaxRecordBytes = 0xF0000000u;

std::uint64_t fnv1a(const char* data, std::size_t n,
                    std::uint64_t h = 1469598103934665603ull) {
    for (std::size_t i = 0; i < n; ++i) {
        h ^= static_cast<unsigned char>(data[i]);
        h *= 1099511628211ull;
    }
    return h;
}

std::string hex(std::uint64_t v) {
    char buffer[17];
    std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(v));
    return buffer;
}

template <class T>
void put(std::string& out, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

void putVec(std::string& out, const Vec3& v) { out.append(reinterpret_cast<const char*>(v.data()), 24); }

void putPairs(std::string& out, const std::vector<collision::ProxyPair>& pairs) {
    put(out, static_cast<std::uint32_t>(pairs.size()));
    for (const collision::ProxyPair& p : pairs) {
        put(out, static_cast<std::uint32_t>(p.a));
        put(out, static_cast<std::uint32_t>(p.b));
    }
}

// The counters a frame keeps, in their order in the file.
constexpr int kCounters = 12;
std::int64_t* counterFields(StepStats& s, int i) {
    std::int64_t* fields[kCounters] = {
        &s.broad.volume_tests, &s.broad.pairs_flagged, &s.broad.volumes_updated,
        &s.broad.swaps,        &s.narrow_tests,        &s.triangle_tests,
        &s.bv_tests,           &s.self_pairs,          &s.refit_nodes,
        &s.toi_queries,        &s.toi_iterations,      &s.toi_events};
    return fields[i];
}

// Reads a record's bytes front to back; every read is bounds-checked against the record.
class Cursor {
public:
    Cursor(const std::string& bytes, std::string what) : b_(bytes), what_(std::move(what)) {}
    template <class T>
    T get() {
        static_assert(std::is_trivially_copyable_v<T>);
        need(sizeof(T));
        T v;
        std::memcpy(&v, b_.data() + at_, sizeof v);
        at_ += sizeof v;
        return v;
    }
    Real real(const char* name) {
        const Real v = get<Real>();
        if (!std::isfinite(v)) fail(std::string(name) + " is not finite");
        return v;
    }
    Vec3 vec(const char* name) { return {real(name), real(name), real(name)}; }
    std::string text(std::size_t n) {
        need(n);
        std::string s = b_.substr(at_, n);
        at_ += n;
        return s;
    }
    std::uint32_t count(std::size_t item_bytes, const char* what) {
        const auto n = get<std::uint32_t>();
        if (std::uint64_t(n) * item_bytes > b_.size() - at_) {
            fail(std::to_string(n) + " " + what + " do not fit in the record");
        }
        return n;
    }
    void end() {
        if (at_ != b_.size()) fail(std::to_string(b_.size() - at_) + " bytes left over");
    }
    [[noreturn]] void fail(const std::string& why) const { throw RecordingError(what_ + ": " + why); }

private:
    void need(std::size_t n) {
        if (n > b_.size() - at_) fail("the record ends early");
    }
    const std::string& b_;
    std::string what_;
    std::size_t at_ = 0;
};

std::string headerYaml(const RecordingHeader& h) {
    YAML::Emitter e;
    e << YAML::BeginMap;
    e << YAML::Key << "format" << YAML::Value << "cdlab-recording";
    e << YAML::Key << "version" << YAML::Value << h.version;
    e << YAML::Key << "scene" << YAML::Value << h.scene.string();
    e << YAML::Key << "scene_hash" << YAML::Value << hex(h.scene_hash);
    e << YAML::Key << "set" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const SceneOverride& o : h.overrides) e << (o.key + "=" + o.value);
    e << YAML::EndSeq;
    e << YAML::Key << "frames" << YAML::Value << h.frames;
    e << YAML::Key << "broadphase" << YAML::Value << h.broad_phase;
    e << YAML::Key << "pair_order" << YAML::Value
      << std::string(collision::pairOrderName(h.pair_order));
    e << YAML::Key << "steps_per_frame" << YAML::Value << h.steps_per_frame;
    e << YAML::Key << "time_step" << YAML::Value << YAML::Precision(17) << double(h.time_step);
    e << YAML::Key << "bodies" << YAML::Value << h.bodies;
    e << YAML::Key << "chains" << YAML::Value << h.chains;
    e << YAML::EndMap;
    return std::string(e.c_str()) + "\n";
}

RecordingHeader parseHeader(const std::string& text, const std::string& file) {
    auto bad = [&](const std::string& why) -> RecordingError {
        return RecordingError(file + ": header: " + why);
    };
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw bad(std::string("not YAML (") + e.what() + ")");
    }
    if (!root.IsMap()) throw bad("not a mapping");
    RecordingHeader h;
    try {
        auto need = [&](const char* key) {
            const YAML::Node n = root[key];
            if (!n) throw bad(std::string("no '") + key + "'");
            return n;
        };
        if (need("format").as<std::string>() != "cdlab-recording") {
            throw bad("format is not cdlab-recording");
        }
        h.version = need("version").as<int>();
        h.scene = need("scene").as<std::string>();
        h.scene_hash = std::stoull(need("scene_hash").as<std::string>(), nullptr, 16);
        for (const YAML::Node& s : need("set")) {
            const std::string kv = s.as<std::string>();
            const std::size_t eq = kv.find('=');
            if (eq == std::string::npos || eq == 0) throw bad("set: '" + kv + "' is not KEY=VALUE");
            h.overrides.push_back({kv.substr(0, eq), kv.substr(eq + 1), "--set"});
        }
        h.frames = need("frames").as<int>();
        h.broad_phase = need("broadphase").as<std::string>();
        const std::optional<collision::PairOrder> order =
            collision::findPairOrder(need("pair_order").as<std::string>());
        if (!order) throw bad("pair_order: unknown");
        h.pair_order = *order;
        h.steps_per_frame = need("steps_per_frame").as<int>();
        h.time_step = need("time_step").as<double>();
        h.bodies = need("bodies").as<std::size_t>();
        h.chains = need("chains").as<std::size_t>();
    } catch (const YAML::Exception& e) {
        throw bad(std::string("a value of the wrong type (") + e.what() + ")");
    } catch (const std::logic_error& e) {  // stoull
        throw bad("scene_hash is not a hexadecimal number");
    }
    if (h.frames < 1 || h.steps_per_frame < 1 || !(h.time_step > 0) || h.bodies < 1) {
        throw bad("frames, steps_per_frame, time_step and bodies must be positive");
    }
    return h;
}

std::string frameBytes(const RecordedFrame& f) {
    std::string out;
    out.reserve(64 + f.state.bodies.size() * 104 + (f.flagged.size() + f.colliding.size()) * 8);
    put(out, static_cast<std::int32_t>(f.frame));
    put(out, f.state.time);
    put(out, f.state.steps);
    put(out, f.state_hash);
    put(out, static_cast<std::uint16_t>(f.broad_phase.size()));
    out += f.broad_phase;
    put(out, static_cast<std::uint32_t>(f.state.bodies.size()));
    for (const BodyMotion& m : f.state.bodies) {
        putVec(out, m.position);
        out.append(reinterpret_cast<const char*>(m.orientation.coeffs().data()), 32);
        putVec(out, m.linear_momentum);
        putVec(out, m.angular_momentum);
    }
    put(out, static_cast<std::uint32_t>(f.state.chains.size()));
    for (const ChainClock& c : f.state.chains) {
        put(out, c.time);
        put(out, static_cast<std::uint8_t>(c.halted ? 1 : 0));
    }
    putPairs(out, f.flagged);
    putPairs(out, f.colliding);
    put(out, static_cast<std::uint32_t>(f.impacts.size()));
    for (const ToiEvent& e : f.impacts) {
        put(out, static_cast<std::uint32_t>(e.a));
        put(out, static_cast<std::uint32_t>(e.b));
        put(out, e.t);
        for (const Pose& p : {e.pose_a, e.pose_b}) {
            putVec(out, p.position);
            out.append(reinterpret_cast<const char*>(p.orientation.coeffs().data()), 32);
        }
        putVec(out, e.point);
        putVec(out, e.normal);
        put(out, static_cast<std::uint8_t>(e.failed ? 1 : 0));
    }
    StepStats counters = f.counters;
    for (int i = 0; i < kCounters; ++i) put(out, *counterFields(counters, i));
    return out;
}

}  // namespace

RecordingHeader recordingHeader(const std::filesystem::path& scene_file,
                                const std::vector<SceneOverride>& overrides, const Scene& scene) {
    RecordingHeader h;
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(scene_file, ec);
    h.scene = (ec ? scene_file : absolute).lexically_normal();
    h.scene_hash = fileHash(scene_file);
    h.overrides = overrides;
    h.frames = scene.frames;
    h.broad_phase = scene.world.broad_phase;
    h.pair_order = scene.world.pair_order;
    h.steps_per_frame = scene.steps_per_frame;
    h.time_step = scene.world.time_step;
    h.bodies = scene.bodies.size();
    h.chains = scene.chains.size();
    return h;
}

RecordedFrame recordFrame(const World& world, int frame) {
    RecordedFrame f;
    f.frame = frame;
    f.state_hash = world.stateHash();
    f.broad_phase = std::string(world.broadPhase().name());
    f.state = world.state();
    f.flagged.assign(world.flaggedPairs().begin(), world.flaggedPairs().end());
    f.colliding.assign(world.collidingPairs().begin(), world.collidingPairs().end());
    f.impacts.assign(world.toiEvents().begin(), world.toiEvents().end());
    StepStats s = world.lastStats();
    for (int i = 0; i < kCounters; ++i) *counterFields(f.counters, i) = *counterFields(s, i);
    return f;
}

std::uint64_t fileHash(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw RecordingError(file.string() + ": cannot be read");
    std::uint64_t h = 1469598103934665603ull;
    char buffer[1 << 16];
    while (in) {
        in.read(buffer, sizeof buffer);
        h = fnv1a(buffer, static_cast<std::size_t>(in.gcount()), h);
    }
    if (in.bad()) throw RecordingError(file.string() + ": cannot be read");
    return h;
}

RecordingWriter::RecordingWriter(const std::filesystem::path& file, const RecordingHeader& header)
    : file_(file), out_(file, std::ios::binary | std::ios::trunc), header_(header) {
    if (!out_) throw RecordingError(file.string() + ": cannot be written");
    const std::string yaml = headerYaml(header);
    std::string head(kMagic, sizeof kMagic);
    put(head, static_cast<std::uint32_t>(header.version));
    put(head, static_cast<std::uint32_t>(yaml.size()));
    head += yaml;
    out_.write(head.data(), static_cast<std::streamsize>(head.size()));
    bytes_ += head.size();
    if (!out_) throw RecordingError(file.string() + ": cannot be written");
}

void RecordingWriter::putRecord(const std::string& record, std::uint32_t tag) {
    std::string framing;
    put(framing, tag);
    put(framing, static_cast<std::uint32_t>(record.size()));
    const std::uint64_t sum = fnv1a(record.data(), record.size());
    out_.write(framing.data(), 8);
    out_.write(record.data(), static_cast<std::streamsize>(record.size()));
    out_.write(reinterpret_cast<const char*>(&sum), 8);
    bytes_ += 16 + record.size();
    if (!out_) throw RecordingError(file_.string() + ": cannot be written (disk full?)");
}

void RecordingWriter::write(const RecordedFrame& frame) {
    if (finished_ || frame.frame != frames_ || frame.state.bodies.size() != header_.bodies ||
        frame.state.chains.size() != header_.chains) {
        throw std::invalid_argument("RecordingWriter::write: frame " +
                                    std::to_string(frame.frame) + " out of turn or shape");
    }
    putRecord(frameBytes(frame), kFrameTag);
    ++frames_;
}

void RecordingWriter::finish(const std::string& ended) {
    if (finished_) return;
    std::string record;
    put(record, static_cast<std::int32_t>(frames_));
    put(record, static_cast<std::uint32_t>(ended.size()));
    record += ended;
    putRecord(record, kEndTag);
    finished_ = true;
    out_.close();
    if (out_.fail()) throw RecordingError(file_.string() + ": cannot be written");
}

Recording Recording::open(const std::filesystem::path& file) {
    Recording r;
    r.file_ = file;
    const std::string name = file.string();
    r.in_.open(file, std::ios::binary);
    if (!r.in_) throw RecordingError(name + ": cannot be opened");
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(file, ec);
    if (ec) throw RecordingError(name + ": cannot be opened (" + ec.message() + ")");
    r.bytes_ = size;
    char magic[8] = {};
    std::uint32_t version = 0, header_bytes = 0;
    r.in_.read(magic, 8);
    if (!r.in_ || std::memcmp(magic, kMagic, 8) != 0) {
        throw RecordingError(name + ": not a cdlab recording (it does not begin with CDLABREC)");
    }
    r.in_.read(reinterpret_cast<char*>(&version), 4);
    r.in_.read(reinterpret_cast<char*>(&header_bytes), 4);
    if (!r.in_) throw RecordingError(name + ": cut short inside its header");
    if (version != static_cast<std::uint32_t>(kRecordingVersion)) {
        throw RecordingError(name + ": recording format version " + std::to_string(version) +
                             "; this cdlab reads version " + std::to_string(kRecordingVersion));
    }
    if (header_bytes > kMaxHeaderBytes || header_bytes > size - 16) {
        throw RecordingError(name + ": the header's length (" + std::to_string(header_bytes) +
                             " bytes) is not that of a recording's header");
    }
    std::string yaml(header_bytes, '\0');
    r.in_.read(yaml.data(), header_bytes);
    r.header_ = parseHeader(yaml, name);
    std::uint64_t at = 16 + header_bytes;
    for (;;) {
        if (at == size) {
            throw RecordingError(name + ": cut short after " + std::to_string(r.offsets_.size()) +
                                 " frames, without its end record (the run that wrote it was "
                                 "stopped before it finished)");
        }
        std::uint32_t tag = 0, length = 0;
        r.in_.seekg(static_cast<std::streamoff>(at));
        r.in_.read(reinterpret_cast<char*>(&tag), 4);
        r.in_.read(reinterpret_cast<char*>(&length), 4);
        const std::string which = tag == kEndTag
                                      ? std::string("the end record")
                                      : "frame " + std::to_string(r.offsets_.size()) + "'s record";
        if (!r.in_ || std::uint64_t(length) + 16 > size - at) {
            throw RecordingError(name + ": cut short inside " + which +
                                 " (the run that wrote it was stopped before it finished)");
        }
        if ((tag != kFrameTag && tag != kEndTag) || length > kMaxRecordBytes) {
            throw RecordingError(name + ": damaged: the record after " +
                                 std::to_string(r.offsets_.size()) +
                                 " frames is neither a frame nor the end");
        }
        if (tag == kFrameTag) {
            r.offsets_.push_back(at);
            at += 16 + std::uint64_t(length);
            continue;
        }
        std::string record(length, '\0');
        std::uint64_t sum = 0;
        r.in_.read(record.data(), length);
        r.in_.read(reinterpret_cast<char*>(&sum), 8);
        if (!r.in_ || sum != fnv1a(record.data(), record.size())) {
            throw RecordingError(name + ": the end record is damaged");
        }
        Cursor c(record, name + ": end record");
        const auto frames = c.get<std::int32_t>();
        r.ended_ = c.text(c.count(1, "characters"));
        c.end();
        if (frames != static_cast<std::int32_t>(r.offsets_.size())) {
            throw RecordingError(name + ": the end record says " + std::to_string(frames) +
                                 " frames, the file holds " + std::to_string(r.offsets_.size()));
        }
        if (at + 16 + length != size) {
            throw RecordingError(name + ": bytes after the end record");
        }
        break;
    }
    if (r.offsets_.empty()) throw RecordingError(name + ": holds no frame");
    return r;
}

RecordedFrame Recording::frame(int k) const {
    const std::string what = file_.string() + ": frame " + std::to_string(k);
    if (k < 0 || k >= frames()) throw RecordingError(what + ": not in the recording");
    std::uint32_t tag = 0, length = 0;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offsets_[static_cast<std::size_t>(k)]));
    in_.read(reinterpret_cast<char*>(&tag), 4);
    in_.read(reinterpret_cast<char*>(&length), 4);
    std::string bytes(length, '\0');
    std::uint64_t sum = 0;
    in_.read(bytes.data(), length);
    in_.read(reinterpret_cast<char*>(&sum), 8);
    if (!in_) throw RecordingError(what + ": cannot be read");
    if (sum != fnv1a(bytes.data(), bytes.size())) {
        throw RecordingError(what + ": damaged (its checksum does not match)");
    }
    Cursor c(bytes, what);
    RecordedFrame f;
    f.frame = c.get<std::int32_t>();
    if (f.frame != k) c.fail("says it is frame " + std::to_string(f.frame));
    f.state.time = c.real("time");
    f.state.steps = c.get<std::int64_t>();
    f.state_hash = c.get<std::uint64_t>();
    f.broad_phase = c.text(c.get<std::uint16_t>());
    if (collision::findBroadPhase(f.broad_phase) == nullptr) {
        c.fail("unknown broad phase '" + f.broad_phase + "'");
    }
    const std::uint32_t n = c.count(104, "bodies");
    if (n != header_.bodies) {
        c.fail(std::to_string(n) + " bodies, the header says " + std::to_string(header_.bodies));
    }
    f.state.bodies.resize(n);
    for (BodyMotion& m : f.state.bodies) {
        m.position = c.vec("a position");
        const Real x = c.real("an orientation"), y = c.real("an orientation"),
                   z = c.real("an orientation"), w = c.real("an orientation");
        m.orientation = Quat(w, x, y, z);
        m.linear_momentum = c.vec("a momentum");
        m.angular_momentum = c.vec("a momentum");
    }
    const std::uint32_t chains = c.count(9, "chains");
    if (chains != header_.chains) c.fail("its chain count is not the header's");
    f.state.chains.resize(chains);
    for (ChainClock& clock : f.state.chains) {
        clock.time = c.real("a chain clock");
        clock.halted = c.get<std::uint8_t>() != 0;
    }
    for (std::vector<collision::ProxyPair>* pairs : {&f.flagged, &f.colliding}) {
        pairs->resize(c.count(8, "pairs"));
        for (collision::ProxyPair& p : *pairs) {
            p.a = static_cast<collision::ProxyId>(c.get<std::uint32_t>());
            p.b = static_cast<collision::ProxyId>(c.get<std::uint32_t>());
            if (!(p.a < p.b) || std::size_t(p.b) >= n) c.fail("a pair of bodies it does not have");
        }
    }
    f.impacts.resize(c.count(177, "times of impact"));
    for (ToiEvent& e : f.impacts) {
        e.a = static_cast<BodyId>(c.get<std::uint32_t>());
        e.b = static_cast<BodyId>(c.get<std::uint32_t>());
        if (e.a == e.b || std::uint32_t(e.a) >= n || std::uint32_t(e.b) >= n) {
            c.fail("an impact of bodies it does not have");
        }
        e.t = c.real("an impact's time");
        for (Pose* p : {&e.pose_a, &e.pose_b}) {
            p->position = c.vec("an impact's pose");
            const Real x = c.real("an impact's pose"), y = c.real("an impact's pose"),
                       z = c.real("an impact's pose"), w = c.real("an impact's pose");
            p->orientation = Quat(w, x, y, z);
        }
        e.point = c.vec("an impact's point");
        e.normal = c.vec("an impact's normal");
        e.failed = c.get<std::uint8_t>() != 0;
    }
    for (int i = 0; i < kCounters; ++i) *counterFields(f.counters, i) = c.get<std::int64_t>();
    c.end();
    return f;
}

}  // namespace engine

// engine/src/scene.cpp -- YAML scene files -> Scene (validated) -> World: the loader's entry
// points. Every value is checked where it is read (scene_parser.h and its parts), and every
// failure throws SceneError with the yaml node's position, "FILE:LINE:COL: key.path: what is
// wrong", so no NaN/Inf, unknown key or out-of-range value gets past the loader. yaml-cpp stays
// in engine/src.
#include "engine/scene.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "scene_parser.h"

namespace engine {

using scene_parsing::formatMessage;
using scene_parsing::SceneParser;
namespace fs = std::filesystem;

namespace {

// Runs the parser; any failure that escaped its key still names a position.
Scene runParser(SceneParser& parser, const std::string& text, const std::string& display_name) {
    try {
        return parser.parse(text);
    } catch (const SceneError&) {
        throw;
    } catch (const YAML::Exception& e) {
        throw SceneError(formatMessage(display_name, e.mark, "scene", e.msg));
    } catch (const std::exception& e) {
        throw SceneError(formatMessage(display_name, YAML::Mark::null_mark(), "scene", e.what()));
    }
}

}  // namespace

Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir) {
    return parseScene(yaml_text, display_name, base_dir, {});
}

Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir,
                 const std::vector<SceneOverride>& overrides) {
    SceneParser parser(display_name, base_dir);
    parser.setOverrides(overrides);
    return runParser(parser, yaml_text, display_name);
}

Scene loadScene(const std::filesystem::path& file) { return loadScene(file, {}); }

Scene loadScene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) {
        throw SceneError(file.string() + ":1:1: scene: cannot open the file (" +
                         (fs::exists(file, ec) ? "not a regular file" : "no such file") + ")");
    }
    // yaml-cpp's nodes take about 100 bytes of memory per byte of a long list (a 50 MB file took
    // 4.8 GB): files past kMaxSceneBytes are refused before parsing. Large populations belong in
    // `repeat:`, which costs a few lines.
    constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t(16) << 20;
    const std::uintmax_t bytes = fs::file_size(file, ec);
    if (!ec && bytes > kMaxSceneBytes) {
        throw SceneError(file.string() + ":1:1: scene: the file has " + std::to_string(bytes) +
                         " bytes, more than the limit of " + std::to_string(kMaxSceneBytes) +
                         " (16 MiB); describe large populations with repeat:");
    }
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in.good() && !in.eof()) {
        throw SceneError(file.string() + ":1:1: scene: cannot read the file");
    }
    fs::path base = file.parent_path();
    if (base.empty()) base = ".";
    SceneParser parser(file.string(), base);
    parser.setOverrides(overrides);
    return runParser(parser, text.str(), file.string());
}

World makeWorld(const Scene& scene) {
    World world(scene.world);
    for (const Body& b : scene.bodies) world.addBody(b);
    for (const ChainSpec& c : scene.chains) world.addChain(c);
    world.detect();
    return world;
}

}  // namespace engine

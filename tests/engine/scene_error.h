// tests/engine/scene_error.h -- what the engine's scene tests share to assert a scene error: the
// message a scene text gives, and its exact "test.yaml:LINE:COL: path: " prefix.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "engine/scene.h"

namespace engine {

/// The error parsing `text` (as "test.yaml", mesh paths relative to `base`) gives, or "" when
/// it parses.
inline std::string sceneErrorOf(
    const std::string& text,
    const std::filesystem::path& base = std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes") {
    try {
        parseScene(text, "test.yaml", base);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

}  // namespace engine

/// Asserts the exact "test.yaml:LINE:COL: path: " prefix and a fragment of the message.
#define EXPECT_SCENE_ERROR(text, prefix, fragment)                                  \
    do {                                                                            \
        const std::string err_ = ::engine::sceneErrorOf(text);                      \
        EXPECT_EQ(err_.rfind(std::string("test.yaml:") + (prefix), 0), 0u) << err_; \
        EXPECT_NE(err_.find(fragment), std::string::npos) << err_;                  \
    } while (false)

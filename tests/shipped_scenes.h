// tests/shipped_scenes.h -- where the tests find the shipped scenes (scenes/ of the repository).
#pragma once

#include <filesystem>

namespace cdlab_test {

/// The repository's scenes/ folder.
inline const std::filesystem::path kScenes = std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes";

}  // namespace cdlab_test

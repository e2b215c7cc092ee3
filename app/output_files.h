// app/output_files.h -- output directories and files that are either complete or absent.
#pragma once

#include <filesystem>
#include <string>

namespace app {

/// Writes `text` to FILE.partial and renames it to `file`, so a file that exists is complete.
/// Throws render::RenderError naming the file on failure.
void writeTextAtomically(const std::filesystem::path& file, const std::string& text);

/// Creates `dir` (and parents) and proves it writable before any work is done.
/// Throws render::RenderError naming the directory on failure.
void prepareOutputDir(const std::filesystem::path& dir);

}  // namespace app

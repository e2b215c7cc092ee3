// app/lab/output_files.h -- output directories and files that are either complete or absent, and
// the lab's files read back whole.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

namespace app {

/// The whole of `file` as bytes; empty when it cannot be read (the caller's parse then says what
/// is missing).
std::string fileBytes(const std::filesystem::path& file);

/// Writes `text` to FILE.partial and renames it to `file`, so a file that exists is complete; an
/// existing `file` that is not a regular file (a device, a FIFO, a link) is refused, never
/// replaced (render/output_file.h). Throws render::RenderError naming the file on failure.
void writeTextAtomically(const std::filesystem::path& file, const std::string& text);

/// writeTextAtomically() for the commands that report instead of throwing: on failure prints the
/// reason to `err` and returns false.
bool writeTextReporting(const std::filesystem::path& file, const std::string& text,
                        std::ostream& err);

/// Creates `dir` (and parents) and proves it writable before any work is done.
/// Throws render::RenderError naming the directory on failure.
void prepareOutputDir(const std::filesystem::path& dir);

/// One run's hold on its output folder: an exclusive flock(2) on the folder itself (no file is
/// made), released when the object goes. A second run into the same folder while the first
/// writes would delete the first's partial files (its video among them) and leave it saying
/// complete; it is refused instead. Throws render::RenderError naming the folder when another
/// process holds it.
class OutputLock {
public:
    explicit OutputLock(const std::filesystem::path& dir);
    ~OutputLock();
    OutputLock(OutputLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;
    OutputLock& operator=(OutputLock&&) = delete;

private:
    int fd_ = -1;
};

/// Removes what an earlier run left in `dir`, so a rerun with fewer frames never shows the old
/// ones beside the new summary: cdlab's own outputs only (frame_NNNNN.png, pause_N.png and .json,
/// summary.json, index.html, and *.partial files of a killed run), and only regular files. Other files stay.
/// Throws render::RenderError when one cannot be removed.
void clearPreviousRun(const std::filesystem::path& dir);

}  // namespace app

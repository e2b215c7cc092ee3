// app/lab/output_files.cpp -- see output_files.h.
#include "output_files.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>

#include "render/image.h"
#include "render/output_file.h"

namespace app {

std::string fileBytes(const std::filesystem::path& file) {
    std::ifstream f(file, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

namespace fs = std::filesystem;

void writeTextAtomically(const fs::path& file, const std::string& text) {
    render::writeFileAtomically(file, text);
}

bool writeTextReporting(const fs::path& file, const std::string& text, std::ostream& err) {
    try {
        writeTextAtomically(file, text);
        return true;
    } catch (const render::RenderError& e) {
        err << e.what() << '\n';
        return false;
    }
}

void prepareOutputDir(const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
        throw render::RenderError("cannot create output directory " + dir.string() +
                                  (ec ? ": " + ec.message() : ""));
    }
    const fs::path probe = dir / ".cdlab-write-test";
    {
        std::ofstream f(probe);
        if (!f) throw render::RenderError("output directory " + dir.string() + " is not writable");
    }
    fs::remove(probe, ec);
}

OutputLock::OutputLock(const fs::path& dir) {
    fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) {
        throw render::RenderError("cannot open output directory " + dir.string() + ": " +
                                  std::strerror(errno));
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int e = errno;
        ::close(fd_);
        fd_ = -1;
        throw render::RenderError(
            "output directory " + dir.string() +
            (e == EWOULDBLOCK ? std::string(" is being written by another cdlab run; wait for it "
                                            "or choose another --out")
                              : ": cannot be locked (" + std::string(std::strerror(e)) + ")"));
    }
}

OutputLock::~OutputLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

namespace {

bool allDigits(std::string_view s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The names run writes into its output folder (app/lab/run_scene.cpp).
bool isRunOutput(const std::string& name) {
    auto strip = [&](std::string_view prefix, std::string_view suffix, std::string_view& middle) {
        if (name.size() < prefix.size() + suffix.size()) return false;
        if (name.compare(0, prefix.size(), prefix) != 0) return false;
        if (name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) return false;
        middle = std::string_view(name).substr(prefix.size(),
                                               name.size() - prefix.size() - suffix.size());
        return true;
    };
    std::string_view middle;
    if (strip("frame_", ".png", middle) && middle.size() == 5 && allDigits(middle)) return true;
    if ((strip("pause_", ".png", middle) || strip("pause_", ".json", middle)) && allDigits(middle)) {
        return true;
    }
    if (name == "summary.json" || name == "index.html") return true;
    return name.find(".partial") != std::string::npos;
}

}  // namespace

void clearPreviousRun(const fs::path& dir) {
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (!isRunOutput(name) || !entry.is_regular_file(ec) || entry.is_symlink(ec)) continue;
        fs::remove(entry.path(), ec);
        if (ec) {
            throw render::RenderError("cannot remove " + entry.path().string() +
                                      " left by an earlier run: " + ec.message());
        }
    }
    if (ec) throw render::RenderError("cannot list output directory " + dir.string() + ": " + ec.message());
}

}  // namespace app

// app/output_files.cpp -- see output_files.h.
#include "output_files.h"

#include <fstream>
#include <system_error>

#include "render/image.h"

namespace app {

namespace fs = std::filesystem;

void writeTextAtomically(const fs::path& file, const std::string& text) {
    const fs::path partial = fs::path(file.string() + ".partial");
    {
        std::ofstream f(partial, std::ios::binary | std::ios::trunc);
        if (!f) throw render::RenderError("cannot write " + partial.string());
        f << text;
        f.flush();
        if (!f) throw render::RenderError("cannot write " + partial.string());
    }
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (ec) throw render::RenderError("cannot rename " + partial.string() + ": " + ec.message());
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

}  // namespace app

// fuzz/recording_fuzz.cpp -- libFuzzer target over the recording reader (engine/recording.h),
// the file `cdlab serve --replay` and `cdlab replay` open. Any input, written to a file, must
// either open and give every frame or throw RecordingError naming the file; a crash, a sanitizer
// report, another exception, a leak, a hang or a huge allocation is a bug. A frame that reads
// must also write back to the same bytes (the reader accepts only what the writer writes).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "engine/recording.h"

namespace {

std::string slurp(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("cdlab_recording_fuzz_" + std::to_string(::getpid()));
    static const bool made = std::filesystem::create_directories(dir) || true;
    (void)made;
    const std::filesystem::path in = dir / "in.rec", out = dir / "out.rec";
    std::ofstream(in, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
        const engine::Recording r = engine::Recording::open(in);
        engine::RecordingWriter w(out, r.header());
        for (int k = 0; k < r.frames(); ++k) w.write(r.frame(k));
        w.finish(r.ended());
        // The header is YAML, which may be written other ways that read the same: compare the
        // records, which follow the header.
        const std::string a = slurp(in), b = slurp(out);
        std::uint32_t ha = 0, hb = 0;
        std::memcpy(&ha, a.data() + 12, 4);
        std::memcpy(&hb, b.data() + 12, 4);
        if (a.substr(16 + ha) != b.substr(16 + hb)) std::abort();
    } catch (const engine::RecordingError& e) {
        if (std::string(e.what()).rfind(in.string(), 0) != 0) std::abort();
    }
    return 0;
}

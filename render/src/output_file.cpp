// render/src/output_file.cpp -- see render/output_file.h.
// Invariant: cdlab renames only over an absent path or a regular file, and writes only into a
// partial file it created itself (O_EXCL | O_NOFOLLOW). A path that is a device, a FIFO, a socket,
// a directory or a symbolic link is refused before any work, and again just before the rename.
// (A path swapped between that last check and rename(2) is outside what this guards: cdlab is not
// a privileged service, and its outputs are the user's own paths.)
#include "render/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <system_error>

#include "render/image.h"

namespace render {

namespace fs = std::filesystem;

namespace {

std::string kindOf(fs::file_type type) {
    switch (type) {
        case fs::file_type::directory: return "a directory";
        case fs::file_type::symlink: return "a symbolic link";
        case fs::file_type::block: return "a block device";
        case fs::file_type::character: return "a character device";
        case fs::file_type::fifo: return "a FIFO";
        case fs::file_type::socket: return "a socket";
        default: return "not a regular file";
    }
}

// The type of `path` itself (a link is a link), or none when absent.
fs::file_type typeOf(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(path, ec);
    if (ec && status.type() != fs::file_type::not_found) {
        throw RenderError(path.string() + ": cannot inspect: " + ec.message());
    }
    return status.type();
}

}  // namespace

void removeQuietly(const fs::path& file) {
    std::error_code ec;
    fs::remove(file, ec);
}

void checkOutputPath(const fs::path& file) {
    const fs::file_type type = typeOf(file);
    if (type == fs::file_type::not_found || type == fs::file_type::regular) return;
    throw RenderError(file.string() + ": exists and is " + kindOf(type) +
                      "; cdlab replaces only regular files (choose another output path)");
}

void claimPartial(const fs::path& partial) {
    const fs::file_type type = typeOf(partial);
    if (type == fs::file_type::not_found) return;
    if (type != fs::file_type::regular) {
        throw RenderError(partial.string() + ": exists and is " + kindOf(type) +
                          "; cdlab writes its temporary files only as new regular files");
    }
    std::error_code ec;
    fs::remove(partial, ec);
    if (ec) throw RenderError(partial.string() + ": cannot remove a stale partial file: " + ec.message());
}

std::FILE* openPartial(const fs::path& partial, const fs::path& file) {
    const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                          0666);
    if (fd < 0) {
        throw RenderError(file.string() + ": cannot write " + partial.string() + ": " +
                          std::error_code(errno, std::generic_category()).message());
    }
    std::FILE* f = ::fdopen(fd, "wb");
    if (f == nullptr) {
        const int err = errno;
        ::close(fd);
        removeQuietly(partial);
        throw RenderError(file.string() + ": cannot write " + partial.string() + ": " +
                          std::error_code(err, std::generic_category()).message());
    }
    return f;
}

void commitPartial(const fs::path& partial, const fs::path& file) {
    try {
        checkOutputPath(file);
    } catch (...) {
        removeQuietly(partial);
        throw;
    }
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (ec) {
        removeQuietly(partial);
        throw RenderError(file.string() + ": cannot rename " + partial.string() + ": " +
                          ec.message());
    }
}

void checkOutputWritable(const fs::path& file) {
    checkOutputPath(file);
    const fs::path partial = fs::path(file.string() + ".partial");
    claimPartial(partial);
    std::fclose(openPartial(partial, file));
    removeQuietly(partial);
}

void writeFileAtomically(const fs::path& file, std::string_view bytes) {
    checkOutputPath(file);
    const fs::path partial = fs::path(file.string() + ".partial");
    claimPartial(partial);
    std::FILE* f = openPartial(partial, file);
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const bool flushed = std::fflush(f) == 0 && std::ferror(f) == 0;
    const int err = errno;
    const bool closed = std::fclose(f) == 0;
    if (!written || !flushed || !closed) {
        removeQuietly(partial);
        throw RenderError(file.string() + ": cannot write " + partial.string() + ": " +
                          std::error_code(err, std::generic_category()).message());
    }
    commitPartial(partial, file);
}

}  // namespace render

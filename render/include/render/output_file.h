// render/output_file.h -- how every cdlab output reaches its final name: written under a
// temporary ".partial" name and renamed when complete, and only ever over a regular file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

#include "render/image.h"  // RenderError

namespace render {

/// Refuses an output path that exists and is not a regular file: a device (`/dev/null`), a FIFO,
/// a socket, a directory or a symbolic link (even one to a regular file) is never replaced or
/// written through. Throws RenderError naming the path and what it is. An absent path or a
/// regular file passes. cdlab's outputs are files it can replace whole; to stream a video or a
/// table elsewhere, write a file and copy it.
void checkOutputPath(const std::filesystem::path& file);

/// Prepares `partial` for a fresh write: a regular file left by a killed run is removed; anything
/// else there (a symbolic link planted to redirect the write, a device, a FIFO) is refused with
/// RenderError.
void claimPartial(const std::filesystem::path& partial);

/// Opens `partial` for writing after claimPartial(), created exclusively (O_EXCL | O_NOFOLLOW, mode
/// 0666 before the umask), so the write cannot follow a link created in between. Throws
/// RenderError naming `file` (the final name) on failure. The caller fcloses it.
std::FILE* openPartial(const std::filesystem::path& partial, const std::filesystem::path& file);

/// Renames a complete `partial` to `file` after checking `file` again (checkOutputPath); on
/// failure removes `partial` and throws RenderError.
void commitPartial(const std::filesystem::path& partial, const std::filesystem::path& file);

/// Proves before any work that `file` can be written: checkOutputPath(), then FILE.partial is
/// created and removed again. Throws RenderError naming what failed (a missing or read-only
/// directory, a path that is not a regular file).
void checkOutputWritable(const std::filesystem::path& file);

/// The whole path: check, claim FILE.partial, write `bytes`, flush, rename. Throws RenderError
/// naming the file; a failure leaves neither `file` changed nor the partial file behind.
void writeFileAtomically(const std::filesystem::path& file, std::string_view bytes);

/// Removes `file` if it is there, ignoring every error: the clean-up of a partial output on a
/// path that is already failing.
void removeQuietly(const std::filesystem::path& file);

}  // namespace render

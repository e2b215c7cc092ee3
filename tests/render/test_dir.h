// tests/render/test_dir.h -- a fresh directory per test, removed when the test ends.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace cdlab_test {

/// `<temp>/<prefix><pid>_<test name>`, emptied on creation and removed on destruction.
class TempDir {
public:
    explicit TempDir(const std::string& prefix) {
        const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = std::filesystem::temp_directory_path() /
                (prefix + std::to_string(::getpid()) + "_" + info->name());
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

/// A fake `ffmpeg` first on PATH (before the rest of it) for the object's lifetime, in `dir`: a
/// shell script with `body` (by default one that exits 3); PATH is restored on destruction, also
/// when the test fails early.
class DeadFfmpegOnPath {
public:
    explicit DeadFfmpegOnPath(const std::filesystem::path& dir,
                              const std::string& body = "exit 3\n") {
        const std::filesystem::path fake = dir / "ffmpeg";
        std::ofstream(fake) << "#!/bin/sh\n" << body;
        std::filesystem::permissions(fake, std::filesystem::perms::owner_all);
        const char* old_path = std::getenv("PATH");
        saved_ = old_path ? old_path : "";
        // Put first, not alone: the fake's body may use the system's tools (cat, printf).
        ::setenv("PATH", (dir.string() + (saved_.empty() ? "" : ":" + saved_)).c_str(), 1);
    }
    ~DeadFfmpegOnPath() { ::setenv("PATH", saved_.c_str(), 1); }
    DeadFfmpegOnPath(const DeadFfmpegOnPath&) = delete;
    DeadFfmpegOnPath& operator=(const DeadFfmpegOnPath&) = delete;

private:
    std::string saved_;
};

}  // namespace cdlab_test

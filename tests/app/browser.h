// tests/app/browser.h -- headless Chromium for the tests of cdlab's HTML pages: load a page from
// disk, let its scripts run, and take the DOM they left or a screenshot; pick attributes out of
// the serialised DOM; count a colour in part of a screenshot.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "cli_run.h"
#include "render/image.h"

namespace cdlab_test {

/// The Chromium binary on PATH ("" when there is none).
inline std::string chromiumBinary() {
    for (const char* name : {"chromium", "chromium-browser"}) {
        const std::string probe = std::string("command -v ") + name + " > /dev/null 2>&1";
        if (std::system(probe.c_str()) == 0) return name;
    }
    return "";
}

/// What a test says when Chromium is missing: the tests of the pages need a real browser.
inline const char* kNoChromium =
    "chromium not found on PATH: the HTML page tests load each page in headless Chromium; "
    "`bash .ci/bootstrap test` installs it (Debian package chromium)";

/// Runs headless Chromium on `page` (plus `query`, e.g. "?sort=x") with `mode`
/// ("--dump-dom" or "--screenshot=FILE") in a 1280x900 window at scale 1, with a fresh profile
/// in `work`, for at most 60 s. Returns stdout (the DOM for --dump-dom); stderr goes to
/// work/chromium.log.
inline std::string runChromium(const std::filesystem::path& page, const std::string& query,
                               const std::string& mode, const std::filesystem::path& work) {
    const std::filesystem::path profile = work / "chromium-profile";
    std::filesystem::remove_all(profile);
    const std::filesystem::path out = work / "chromium.out";
    const std::string cmd = "timeout 60 " + chromiumBinary() +
                            " --headless --no-sandbox --disable-gpu --disable-dev-shm-usage "
                            "--no-first-run --hide-scrollbars --force-device-scale-factor=1 "
                            "--window-size=1280,900 --virtual-time-budget=3000 --user-data-dir=" +
                            profile.string() + " " + mode + " 'file://" +
                            std::filesystem::absolute(page).string() + query + "' > " +
                            out.string() + " 2> " + (work / "chromium.log").string();
    std::system(cmd.c_str());
    return slurp(out);
}

/// The start tag of the element with id `id` in `dom` ("" when there is none).
inline std::string startTag(const std::string& dom, const std::string& id) {
    const std::size_t at = dom.find("id=\"" + id + "\"");
    if (at == std::string::npos) return "";
    const std::size_t open = dom.rfind('<', at);
    const std::size_t close = dom.find('>', at);
    return dom.substr(open, close - open + 1);
}

/// The value of attribute `name` in a start tag ("" when absent).
inline std::string attribute(const std::string& tag, const std::string& name) {
    const std::string key = " " + name + "=\"";
    const std::size_t at = tag.find(key);
    if (at == std::string::npos) return "";
    const std::size_t begin = at + key.size();
    return tag.substr(begin, tag.find('"', begin) - begin);
}

/// Occurrences of `needle` in `text`.
inline int countOf(const std::string& text, const std::string& needle) {
    int n = 0;
    for (std::size_t at = text.find(needle); at != std::string::npos;
         at = text.find(needle, at + needle.size())) {
        ++n;
    }
    return n;
}

/// Pixels of a screenshot within 40 per channel of `rgb` inside `rect`, "x,y,width,height" in
/// page pixels (a page's data-rect attribute).
inline int pixelsInRect(const render::Image& image, const std::string& rect,
                        std::array<int, 3> rgb) {
    int x0 = 0, y0 = 0, w = 0, h = 0;
    char sep = 0;
    std::stringstream(rect) >> x0 >> sep >> y0 >> sep >> w >> sep >> h;
    int n = 0;
    for (int y = std::max(y0, 0); y < std::min(y0 + h, image.height); ++y) {
        for (int x = std::max(x0, 0); x < std::min(x0 + w, image.width); ++x) {
            const std::uint8_t* p = image.pixel(x, y);
            n += std::abs(p[0] - rgb[0]) <= 40 && std::abs(p[1] - rgb[1]) <= 40 &&
                 std::abs(p[2] - rgb[2]) <= 40;
        }
    }
    return n;
}

}  // namespace cdlab_test

// tests/test_scale.h -- how large the suite's large loops run. CDLAB_TEST_SCALE (a number in
// (0, 1], default 1) shrinks the trial counts and sizes of the tests that repeat one code path many
// times, so the sanitizer tier (.ci/bootstrap check-all sets 0.1) runs every test and every code
// path without repeating the large loops. Release runs at full size.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace cdlab_test {

/// CDLAB_TEST_SCALE, read once. A value that is not a number in (0, 1] stops the test binary with
/// a message: a typo must not silently run the full or an empty suite.
inline double testScale() {
    static const double scale = [] {
        const char* text = std::getenv("CDLAB_TEST_SCALE");
        if (text == nullptr || *text == '\0') return 1.0;
        char* end = nullptr;
        const double v = std::strtod(text, &end);
        if (end == text || *end != '\0' || !(v > 0 && v <= 1)) {
            std::fprintf(stderr, "CDLAB_TEST_SCALE=%s: must be a number in (0, 1]\n", text);
            std::exit(2);
        }
        return v;
    }();
    return scale;
}

/// n at the current scale, never below at_least (nor above n): the count a scaled loop runs.
inline int scaled(int n, int at_least = 1) {
    const int s = static_cast<int>(std::lround(n * testScale()));
    return std::min(n, std::max(at_least, s));
}

}  // namespace cdlab_test

// tests/bench/http_servers/bench_server.cpp -- what every backend answers alike.
#include "bench_server.h"

#include <charconv>

namespace httpbench {

std::uint64_t parseVersion(std::string_view text) {
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    return ec == std::errc() && end == text.data() + text.size() ? v : 0;
}

std::uint64_t afterParam(std::string_view query) {
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string_view pair = query.substr(0, amp);
        if (pair.substr(0, 6) == "after=") return parseVersion(pair.substr(6));
        if (amp == std::string_view::npos) break;
        query.remove_prefix(amp + 1);
    }
    return 0;
}

std::string commandAnswer(const Frame& f) {
    return "{\"ok\":true,\"version\":" + std::to_string(f.version) +
           ",\"published_ns\":" + std::to_string(f.published_ns) + "}";
}

}  // namespace httpbench

// app/lab/serve/pair_history.cpp -- see pair_history.h.
#include "serve/pair_history.h"

#include <algorithm>

namespace app {

void PairHistory::add(int frame, std::span<const collision::ProxyPair> flagged,
                      std::span<const collision::ProxyPair> colliding) {
    if (frame != frames() || full_) return;
    if (kept_ + flagged.size() + colliding.size() > kMaxPairs) {
        full_ = true;
        return;
    }
    auto keep = [](std::vector<std::vector<collision::ProxyPair>>& list,
                   std::span<const collision::ProxyPair> pairs) {
        std::vector<collision::ProxyPair> sorted(pairs.begin(), pairs.end());
        std::sort(sorted.begin(), sorted.end());
        list.push_back(std::move(sorted));
    };
    keep(flagged_, flagged);
    keep(colliding_, colliding);
    kept_ += flagged.size() + colliding.size();
}

PairHistory::Ranges PairHistory::of(collision::ProxyId a, collision::ProxyId b) const {
    const collision::ProxyPair p{std::min(a, b), std::max(a, b)};
    Ranges out;
    out.frames = frames();
    auto collect = [&](const std::vector<std::vector<collision::ProxyPair>>& per_frame,
                       std::vector<std::pair<int, int>>& ranges) {
        for (int f = 0; f < frames(); ++f) {
            const auto& list = per_frame[std::size_t(f)];
            if (!std::binary_search(list.begin(), list.end(), p)) continue;
            if (!ranges.empty() && ranges.back().second == f - 1) {
                ranges.back().second = f;
            } else {
                ranges.emplace_back(f, f);
            }
        }
    };
    collect(flagged_, out.flagged);
    collect(colliding_, out.colliding);
    return out;
}

}  // namespace app

// app/lab/bench/boxpruning_shim/boxpruning_radix.cpp -- the radix sort the BoxPruning shim declares.
// Floats become unsigned keys in the same order (sign bit flipped for positives, all bits for
// negatives: Herf, "Radix Tricks", 2001), then four stable 8-bit counting passes.
#include <array>
#include <cstring>

#include "Stdafx.h"

RadixSort& RadixSort::Sort(const float* input, udword nb) {
    if (nb == 0) return *this;
    keys_.resize(nb);
    ranks_.resize(nb);
    spare_.resize(nb);
    for (udword i = 0; i < nb; ++i) {
        udword bits;
        std::memcpy(&bits, &input[i], sizeof bits);
        keys_[i] = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
        ranks_[i] = i;
    }
    std::array<std::array<udword, 256>, 4> counts{};
    for (udword i = 0; i < nb; ++i) {
        for (int pass = 0; pass < 4; ++pass) ++counts[pass][(keys_[i] >> (8 * pass)) & 0xff];
    }
    udword* from = ranks_.data();
    udword* to = spare_.data();
    for (int pass = 0; pass < 4; ++pass) {
        if (counts[pass][(keys_[0] >> (8 * pass)) & 0xff] == nb) continue;  // one bucket: no-op
        udword offset = 0;
        std::array<udword, 256> start;
        for (int b = 0; b < 256; ++b) {
            start[b] = offset;
            offset += counts[pass][b];
        }
        for (udword i = 0; i < nb; ++i) {
            const udword r = from[i];
            to[start[(keys_[r] >> (8 * pass)) & 0xff]++] = r;
        }
        std::swap(from, to);
    }
    if (from != ranks_.data()) ranks_.swap(spare_);
    return *this;
}

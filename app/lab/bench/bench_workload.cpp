// app/lab/bench/bench_workload.cpp -- moving-box workloads and the reference pair count.
// Determinism: all randomness comes from one splitmix64 stream per workload, converted to doubles
// by hand (not by std:: distributions, whose algorithms are implementation-defined), and the
// motion is plain double arithmetic in a fixed order, so every process that builds the same
// workload and steps it the same number of times sees bit-identical boxes.
#include "bench_workload.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace app {

using collision::Aabb;
using collision::ProxyId;
using collision::Real;
using collision::Vec3;

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

class Random {
public:
    explicit Random(std::uint64_t seed) : state_(seed) {}
    /// Uniform in [0, 1): the top 53 bits of the next output.
    double unit() {
        state_ += 0x9E3779B97F4A7C15ull;
        return static_cast<double>(splitmix64(state_) >> 11) * 0x1.0p-53;
    }
    double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }

private:
    std::uint64_t state_;
};

/// MSVC's rand(): the linear congruential generator Terdiman's scenes were made with, so the
/// BoxPruning workload is his boxes exactly (11,811 overlapping pairs at 10,000 boxes, seed 42).
int msvcRand(std::uint32_t& state) {
    state = state * 214013u + 2531011u;
    return static_cast<int>((state >> 16) & 0x7fffu);
}

constexpr int kBoxPruningRange = 2048;  // centres in [-2048, 2047]
constexpr int kBoxPruningHalf = 127;    // half extents in [0, 127]

}  // namespace

std::string_view workloadName(WorkloadKind kind) {
    switch (kind) {
        case WorkloadKind::Uniform:
            return "uniform";
        case WorkloadKind::Mixed:
            return "mixed";
        case WorkloadKind::Wide:
            return "wide";
        case WorkloadKind::BoxPruning:
            return "boxpruning";
    }
    return "?";
}

std::optional<WorkloadKind> parseWorkloadKind(std::string_view name) {
    if (name == "uniform") return WorkloadKind::Uniform;
    if (name == "mixed") return WorkloadKind::Mixed;
    if (name == "wide") return WorkloadKind::Wide;
    if (name == "boxpruning") return WorkloadKind::BoxPruning;
    return std::nullopt;
}

std::uint64_t pairHash(ProxyId a, ProxyId b) {
    return splitmix64((static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
                      static_cast<std::uint32_t>(b));
}

MovingBoxes::MovingBoxes(WorkloadKind kind, int n, std::uint64_t seed) : kind_(kind) {
    if (kind == WorkloadKind::BoxPruning) {
        generateBoxPruning(n, seed);
        return;
    }
    const std::uint64_t stream = kind == WorkloadKind::Uniform ? 0x1234u
                                 : kind == WorkloadKind::Mixed ? 0x5678u
                                                               : 0x9abcu;
    Random random(splitmix64(seed) ^ stream);
    const std::size_t count = static_cast<std::size_t>(std::max(n, 2));
    unit_.resize(count);
    half_.resize(count);
    velocity_.resize(count);
    Real largest = 0;
    for (std::size_t i = 0; i < count; ++i) {
        Vec3 h;
        if (kind == WorkloadKind::Uniform) {
            h = Vec3(random.uniform(0.4, 0.6), random.uniform(0.4, 0.6), random.uniform(0.4, 0.6));
        } else {
            // Log-uniform scale over two decades (mixed) or four (wide), then a mild per-axis
            // jitter.
            const double scale = kind == WorkloadKind::Mixed
                                     ? 0.05 * std::pow(100.0, random.unit())
                                     : 0.005 * std::pow(10000.0, random.unit());
            h = Vec3(scale * random.uniform(0.8, 1.2), scale * random.uniform(0.8, 1.2),
                     scale * random.uniform(0.8, 1.2));
        }
        half_[i] = h;
        largest = std::max(largest, h.maxCoeff());
        unit_[i] = Vec3(random.unit(), random.unit(), random.unit());
        // Direction uniform on the sphere (Archimedes: z uniform in [-1, 1]); speed 1-2 % of the
        // box's size per frame.
        const double z = random.uniform(-1.0, 1.0);
        const double phi = random.uniform(0.0, 2 * std::numbers::pi);
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        const double size = 2 * h.sum() / 3;
        const double speed = size * random.uniform(0.01, 0.02);
        velocity_[i] = Vec3(r * std::cos(phi), r * std::sin(phi), z) * speed;
    }

    // Calibrate the side. Two boxes with centres uniform in a cube of side L overlap with
    // probability prod_k 2 (ha_k + hb_k) / L (walls ignored), so pairs / N is about
    // (N - 1) / 2 * E[prod_k 2 (ha_k + hb_k)] / L^3. Estimate the expectation on sampled pairs,
    // then correct for the walls (centres are kept h away from them) by measuring.
    double mean_product = 0;
    const int samples = 20000;
    for (int s = 0; s < samples; ++s) {
        const auto a = static_cast<std::size_t>(random.unit() * static_cast<double>(count));
        const auto b = static_cast<std::size_t>(random.unit() * static_cast<double>(count));
        mean_product += 8 * (half_[a] + half_[b]).prod();
    }
    mean_product /= samples;
    const double target = kTargetPairsPerBody * static_cast<double>(count);
    side_ = std::cbrt(static_cast<double>(count - 1) / 2 * mean_product / kTargetPairsPerBody);
    side_ = std::max(side_, 4 * largest);
    PairReference reference;
    for (int iteration = 0; iteration < 8; ++iteration) {
        place();
        const double pairs = static_cast<double>(reference.count(*this).pairs);
        const double ratio = std::max(pairs, 1.0) / target;
        if (std::abs(ratio - 1) < 0.01) break;
        side_ = std::max<double>(side_ * std::cbrt(ratio), 4 * largest);
    }
    place();
}

void MovingBoxes::generateBoxPruning(int n, std::uint64_t seed) {
    // Terdiman, "Box pruning revisited" (2017), the benchmark's RunPerformanceTest: per box three
    // centre coordinates, then three half extents, each from one rand() call.
    rand_state_ = static_cast<std::uint32_t>(41 + seed);
    const std::size_t count = static_cast<std::size_t>(std::max(n, 2));
    center_.resize(count);
    half_.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        for (int k = 0; k < 3; ++k) {
            center_[i][k] = Real((msvcRand(rand_state_) & 4095) - kBoxPruningRange);
        }
        for (int k = 0; k < 3; ++k) half_[i][k] = Real(msvcRand(rand_state_) & kBoxPruningHalf);
    }
    lower_ = -kBoxPruningRange - kBoxPruningHalf;
    side_ = 2 * (kBoxPruningRange + kBoxPruningHalf) - 1;
    frame_ = 0;
    makeBoxes();
}

void MovingBoxes::jitter() {
    for (Vec3& c : center_) {
        for (int k = 0; k < 3; ++k) {
            const Real moved = c[k] + Real(msvcRand(rand_state_) % 3 - 1);
            c[k] = std::clamp(moved, Real(-kBoxPruningRange), Real(kBoxPruningRange - 1));
        }
    }
    ++frame_;
    makeBoxes();
}

void MovingBoxes::place() {
    center_.resize(unit_.size());
    for (std::size_t i = 0; i < unit_.size(); ++i) {
        const Vec3 room = Vec3::Constant(side_) - 2 * half_[i];
        center_[i] = half_[i] + unit_[i].cwiseProduct(room);
    }
    frame_ = 0;
    makeBoxes();
}

void MovingBoxes::step() {
    if (kind_ == WorkloadKind::BoxPruning) {
        jitter();
        return;
    }
    for (std::size_t i = 0; i < center_.size(); ++i) {
        Vec3& c = center_[i];
        Vec3& v = velocity_[i];
        c += v;
        for (int k = 0; k < 3; ++k) {
            const Real lo = half_[i][k];
            const Real hi = side_ - half_[i][k];
            if (c[k] < lo) {
                c[k] = 2 * lo - c[k];
                v[k] = -v[k];
            } else if (c[k] > hi) {
                c[k] = 2 * hi - c[k];
                v[k] = -v[k];
            }
        }
    }
    ++frame_;
    makeBoxes();
}

void MovingBoxes::makeBoxes() {
    box_.resize(center_.size());
    for (std::size_t i = 0; i < center_.size(); ++i) {
        box_[i] = collision::Aabb{center_[i] - half_[i], center_[i] + half_[i]};
    }
}

void MovingBoxes::volumes(std::vector<collision::ProxyVolumes>& out) const {
    out.resize(center_.size());
    for (std::size_t i = 0; i < center_.size(); ++i) {
        collision::ProxyVolumes& v = out[i];
        v.aabb = box_[i];
        v.sphere.center = center_[i];
        v.sphere.radius = half_[i].norm();
        v.obb.center = center_[i];
        v.obb.axes = collision::Mat3::Identity();
        v.obb.half_extents = half_[i];
    }
}

PairSummary PairReference::count(const MovingBoxes& boxes) {
    const int n = boxes.size();
    // Slab width: four median y extents, so a typical box touches one or two slabs.
    extents_.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) extents_[i] = 2 * boxes.halfExtents()[i].y();
    const auto mid = extents_.begin() + n / 2;
    std::nth_element(extents_.begin(), mid, extents_.end());
    const Real width = std::max(4 * *mid, boxes.side() / 4096);
    const int slabs = std::max(1, static_cast<int>(std::ceil(boxes.side() / width)));
    const Real lower = boxes.lower();
    auto slabOf = [&](Real y) {
        return std::clamp(static_cast<int>(std::floor((y - lower) / width)), 0, slabs - 1);
    };

    // Counting sort of (slab, box) entries by slab.
    slab_start_.assign(static_cast<std::size_t>(slabs) + 1, 0);
    for (int i = 0; i < n; ++i) {
        const Aabb box = boxes.aabb(i);
        for (int s = slabOf(box.min.y()); s <= slabOf(box.max.y()); ++s) ++slab_start_[s + 1];
    }
    for (int s = 0; s < slabs; ++s) slab_start_[s + 1] += slab_start_[s];
    entries_.resize(static_cast<std::size_t>(slab_start_.back()));
    {
        std::vector<int> fill(slab_start_.begin(), slab_start_.end() - 1);
        for (int i = 0; i < n; ++i) {
            const Aabb box = boxes.aabb(i);
            for (int s = slabOf(box.min.y()); s <= slabOf(box.max.y()); ++s) {
                entries_[static_cast<std::size_t>(fill[s]++)] = Entry{box, i};
            }
        }
    }

    PairSummary out;
    for (int s = 0; s < slabs; ++s) {
        const auto begin = entries_.begin() + slab_start_[s];
        const auto end = entries_.begin() + slab_start_[s + 1];
        std::sort(begin, end, [](const Entry& a, const Entry& b) {
            return a.box.min.x() != b.box.min.x() ? a.box.min.x() < b.box.min.x() : a.id < b.id;
        });
        for (auto p = begin; p != end; ++p) {
            const Aabb& a = p->box;
            // Sorted by min x, so x overlaps exactly while the next min x <= this max x.
            for (auto q = p + 1; q != end && q->box.min.x() <= a.max.x(); ++q) {
                const Aabb& b = q->box;
                if (a.min.y() <= b.max.y() && b.min.y() <= a.max.y() && a.min.z() <= b.max.z() &&
                    b.min.z() <= a.max.z() && slabOf(std::max(a.min.y(), b.min.y())) == s) {
                    ++out.pairs;
                    out.hash += p->id < q->id ? pairHash(p->id, q->id) : pairHash(q->id, p->id);
                }
            }
        }
    }
    return out;
}

PairSummary summarizePairs(std::span<const collision::ProxyPair> pairs) {
    PairSummary out;
    out.pairs = static_cast<std::int64_t>(pairs.size());
    for (const collision::ProxyPair& p : pairs) out.hash += pairHash(p.a, p.b);
    return out;
}

}  // namespace app

// app/lab/bench/boxpruning_shim/Stdafx.h -- what Terdiman's BoxPruning17/IceBoxPruning.cpp
// (github.com/Pierre-Terdiman/BoxPruning, "Box pruning revisited", 2017) takes from his Windows
// support library, written for GCC/Clang so that his file compiles with two mechanical edits
// that app/CMakeLists.txt makes to a build-directory copy: MSVC's `_asm align 16` lines are
// dropped, and `const udword Index1 = ` becomes `udword Index1; Index1 = ` (MSVC lets a goto
// jump over an initialised local; GCC does not).
// Only the names his file uses are here: fixed-width types, MSVC's __forceinline,
// __declspec(align) and _aligned_malloc, an AABB of six floats, a pair container and a radix
// sort with his interface (ours: boxpruning_radix.cpp). Bench only: never part of the library.
#pragma once

#include <xmmintrin.h>

#include <cassert>
#include <cfloat>
#include <cstdint>
#include <cstdlib>
#include <vector>

using udword = std::uint32_t;
using sdword = std::int32_t;
using ubyte = std::uint8_t;

#define __forceinline inline __attribute__((always_inline))
#define __declspec(spec) BOXPRUNING_SHIM_DECLSPEC_##spec
#define BOXPRUNING_SHIM_DECLSPEC_align(n) alignas(n)
#define FUNCTION
#define MESHMERIZER_API
#define DELETEARRAY(p) \
    do {               \
        delete[](p);   \
        (p) = nullptr; \
    } while (0)

inline void* _aligned_malloc(std::size_t size, std::size_t alignment) {
    // std::aligned_alloc wants a size that is a multiple of the alignment.
    return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}
inline void _aligned_free(void* p) { std::free(p); }

struct Point {
    float x, y, z;
};

/// Six contiguous floats: min x y z, then max x y z (his code loads 4 floats from &mMin.x).
struct AABB {
    Point mMin;
    Point mMax;
    /// Closed-interval overlap on every axis.
    bool Intersect(const AABB& o) const {
        return !(mMax.x < o.mMin.x || o.mMax.x < mMin.x || mMax.y < o.mMin.y || o.mMax.y < mMin.y ||
                 mMax.z < o.mMin.z || o.mMax.z < mMin.z);
    }
};

/// A growing list of 32-bit values; pairs are stored as two consecutive entries.
class Container {
public:
    udword GetNbEntries() const { return static_cast<udword>(entries_.size()); }
    const udword* GetEntries() const { return entries_.data(); }
    void Reset() { entries_.clear(); }
    void Add(udword a, udword b) {
        entries_.push_back(a);
        entries_.push_back(b);
    }

private:
    std::vector<udword> entries_;
};

/// Adds pairs (id0, id1) to a Container.
class Pairs {
public:
    explicit Pairs(Container& container) : container_(container) {}
    __forceinline void AddPair(udword id0, udword id1) { container_.Add(id0, id1); }

private:
    Container& container_;
};

/// Least-significant-digit radix sort of floats by value, 8 bits a pass, returning the ranks
/// (indices in sorted order). GetRecyclable() is a second buffer of the same size the caller
/// may overwrite while it reads the ranks.
class RadixSort {
public:
    RadixSort& Sort(const float* input, udword nb);
    udword* GetRanks() const { return const_cast<udword*>(ranks_.data()); }
    udword* GetRecyclable() const { return const_cast<udword*>(spare_.data()); }

private:
    std::vector<udword> ranks_;
    std::vector<udword> spare_;
    std::vector<udword> keys_;
};

namespace Meshmerizer {
bool CompleteBoxPruning(udword nb, const AABB* list, Container& pairs);
bool BipartiteBoxPruning(udword nb0, const AABB* list0, udword nb1, const AABB* list1,
                         Container& pairs);
}  // namespace Meshmerizer

#define USE_HARDCODED_AXES
#define USE_DIRECT_BOUNDS

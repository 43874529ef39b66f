#pragma once
// Helpers for the per-pixel loops of reproject/ (internal): four floats side by side, and the
// pixels of a row side by side (eight with AVX2, else four), in GCC / Clang vector extensions
// (SSE or AVX2 on x86-64, NEON on ARM, plain code elsewhere); sparse marks eight at a time.
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__AVX2__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace parallax::simd {

// The largest finite float: `value <= kFloatMax` is false for +inf and NaN, lane by lane too.
constexpr float kFloatMax = std::numeric_limits<float>::max();

// Comparisons give -1 (true) or 0 per lane.
using F4 = float __attribute__((vector_size(16)));
using I4 = int32_t __attribute__((vector_size(16)));

// Bit k set where lane k of a comparison result is true.
inline int LaneBits(I4 mask) {
#if defined(__SSE2__)
  return _mm_movemask_ps(reinterpret_cast<__m128>(mask));
#else
  return (mask[0] & 1) | (mask[1] & 2) | (mask[2] & 4) | (mask[3] & 8);
#endif
}

// Pixels of a row side by side (a textured block's groups): eight where the build has AVX2
// (x86-64-v3, cmake/cpu_level.cmake), else four.
#if defined(__AVX2__)
constexpr int kLanes = 8;
using FV = float __attribute__((vector_size(32)));
using IV = int32_t __attribute__((vector_size(32)));
inline int LaneBits(IV mask) { return _mm256_movemask_ps(reinterpret_cast<__m256>(mask)); }
#else
constexpr int kLanes = 4;
using FV = F4;
using IV = I4;
#endif

// 0, 1, 2, ... per lane.
inline IV LaneIndices() {
  IV index;
  for (int k = 0; k < kLanes; ++k) index[k] = k;
  return index;
}

// A vector of floats from anywhere (no alignment needed), and back.
template <typename V>
V Load(const float* p) {
  V value;
  std::memcpy(&value, p, sizeof(value));
  return value;
}
template <typename V>
void Store(float* p, V value) {
  std::memcpy(p, &value, sizeof(value));
}
inline F4 Load4(const float* p) { return Load<F4>(p); }
inline void Store4(float* p, F4 value) { Store(p, value); }

// Calls f(x) for every x in [0, count) with marks[x] != 0, skipping eight marks at a time
// where all are 0 (for sparse marks: edges, silhouettes, holes).
template <typename F>
void ForEachMarked(const uint8_t* marks, int count, F&& f) {
  for (int x = 0; x < count;) {
    if (x + 8 <= count) {
      uint64_t eight;
      std::memcpy(&eight, marks + x, sizeof(eight));
      if (eight == 0) {
        x += 8;
        continue;
      }
    }
    if (marks[x] != 0) f(x);
    ++x;
  }
}

}  // namespace parallax::simd

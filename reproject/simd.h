#pragma once
// Four floats side by side for the per-pixel loops of reproject/ (internal), in GCC / Clang
// vector extensions: SSE on x86-64, NEON on ARM, plain code elsewhere.
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace parallax::simd {

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

// Four floats from anywhere (no alignment needed), and back.
inline F4 Load4(const float* p) {
  F4 value;
  std::memcpy(&value, p, sizeof(value));
  return value;
}
inline void Store4(float* p, F4 value) { std::memcpy(p, &value, sizeof(value)); }

}  // namespace parallax::simd

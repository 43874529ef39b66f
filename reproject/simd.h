#pragma once
// Helpers for the per-pixel loops of reproject/ (internal): four floats side by side, and the
// pixels of a row side by side (eight with AVX2, else four), in GCC / Clang vector extensions
// (SSE or AVX2 on x86-64, NEON on ARM, plain code elsewhere); four floats as half floats;
// sparse marks eight at a time.
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__AVX2__) || defined(__F16C__)
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

// Four floats as IEEE half floats (binary16, rounded to nearest even; 8 bytes), and back: the
// warp buffers' color and weight. Portable integer arithmetic here; with F16C (x86-64-v3)
// StoreHalf4 and LoadHalf4 below use its instructions, with the same results (NaN payloads
// aside).
using U4 = uint32_t __attribute__((vector_size(16)));
using H4 = uint16_t __attribute__((vector_size(8)));  // Four halves' bits.

inline U4 Bits(F4 value) {
  U4 bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}
inline F4 FromBits(U4 bits) {
  F4 value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

// Halves in the low 16 bits of each lane.
inline U4 HalfBitsPortable(F4 value) {
  const U4 bits = Bits(value);
  const U4 sign = (bits >> 16) & 0x8000u;
  const U4 magnitude = bits & 0x7fffffffu;
  // 65520 (2^15 (2 - 2^-11)) and above round to infinity; NaN stays a (quiet) NaN.
  const U4 overflow = magnitude > 0x7f800000u ? 0x7e00u : 0x7c00u;
  // Below 2^-14, a half is a multiple of 2^-24: adding 0.5 (2^-1) makes the float's own
  // rounding (to nearest even) round the value to that multiple, left in the low mantissa bits.
  const F4 subnormal_sum = FromBits(magnitude) + 0.5f;
  const U4 subnormal = Bits(subnormal_sum) - 0x3f000000u;
  // Normal: rebias the exponent (127 -> 15) and drop 13 mantissa bits, rounding to nearest
  // even: add half a unit less one, plus the lowest kept bit (a carry into the exponent is
  // right, up to infinity).
  const U4 odd = (magnitude >> 13) & 1u;
  const U4 normal = (magnitude - ((127u - 15u) << 23) + 0xfffu + odd) >> 13;
  const U4 half = magnitude >= 0x47800000u  ? overflow
                  : magnitude < 0x38800000u ? subnormal
                                            : normal;
  return half | sign;
}

inline F4 FromHalfBitsPortable(U4 half) {
  const U4 sign = (half & 0x8000u) << 16;
  const U4 shifted = (half & 0x7fffu) << 13;  // Exponent and mantissa where a float has them.
  // Read as a float, that is the half with the exponent's bias 127 instead of 15: times 2^112
  // it is the half's value, exactly (subnormals, exponent 0, come out normal). Infinity and
  // NaN (exponent 31) take the float's largest exponent instead.
  const F4 scaled = FromBits(shifted) * 0x1p112f;
  const U4 magnitude = shifted >= (0x7c00u << 13) ? shifted | 0x7f800000u : Bits(scaled);
  return FromBits(magnitude | sign);
}

inline void StoreHalf4(uint16_t* p, F4 value) {
#if defined(__F16C__)
  const __m128i half = _mm_cvtps_ph(reinterpret_cast<__m128>(value), _MM_FROUND_TO_NEAREST_INT);
  _mm_storel_epi64(reinterpret_cast<__m128i*>(p), half);
#else
  const H4 half = __builtin_convertvector(HalfBitsPortable(value), H4);
  std::memcpy(p, &half, sizeof(half));
#endif
}

inline F4 LoadHalf4(const uint16_t* p) {
#if defined(__F16C__)
  return reinterpret_cast<F4>(_mm_cvtph_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
#else
  H4 half;
  std::memcpy(&half, p, sizeof(half));
  return FromHalfBitsPortable(__builtin_convertvector(half, U4));
#endif
}

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

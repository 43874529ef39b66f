#include "reproject/simd.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace parallax::simd {
namespace {

// The compiler's own conversions (_Float16, round to nearest even) are the reference.
uint16_t ReferenceHalf(float value) {
  const _Float16 half = static_cast<_Float16>(value);
  uint16_t bits;
  std::memcpy(&bits, &half, sizeof(bits));
  return bits;
}

float ReferenceFloat(uint16_t bits) {
  _Float16 half;
  std::memcpy(&half, &bits, sizeof(half));
  return static_cast<float>(half);
}

float FloatFromBits(uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

TEST(Simd, EveryHalfConvertsToTheSameFloatAsTheCompiler) {
  int mismatches = 0;
  for (uint32_t bits = 0; bits < 0x10000u; bits += 4) {
    const U4 halves = {bits, bits + 1, bits + 2, bits + 3};
    const F4 values = FromHalfBitsPortable(halves);
    for (int k = 0; k < 4; ++k) {
      const float expected = ReferenceFloat(static_cast<uint16_t>(halves[k]));
      const bool same = std::isnan(expected) ? std::isnan(values[k])
                                             : std::memcmp(&expected, &values[k], sizeof(float)) == 0;
      mismatches += same ? 0 : 1;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(Simd, FloatsRoundToTheSameHalfAsTheCompiler) {
  // Every 4099th float bit pattern (all exponents, both signs, NaNs), and the edges: the
  // largest half, the rounding to infinity, the smallest normal and subnormal halves and the
  // ties between them (to even).
  std::vector<float> values;
  for (uint64_t bits = 0; bits <= 0xffffffffu; bits += 4099) values.push_back(FloatFromBits(static_cast<uint32_t>(bits)));
  for (const float edge : {0.0f, 65504.0f, 65519.99f, 65520.0f, 65536.0f, 0x1p-14f, 0x1p-24f,
                           0x1p-25f, 0x1.000002p-25f, 0x3p-25f, 0x1.ffcp-15f, 0x1.ffep-15f,
                           1.0f + 0x1p-11f, 1.0f + 0x3p-11f, std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::denorm_min()}) {
    values.push_back(edge);
    values.push_back(-edge);
  }
  while (values.size() % 4 != 0) values.push_back(0.5f);
  int mismatches = 0;
  for (size_t i = 0; i < values.size(); i += 4) {
    const F4 four = {values[i], values[i + 1], values[i + 2], values[i + 3]};
    const U4 halves = HalfBitsPortable(four);
    for (int k = 0; k < 4; ++k) {
      const uint16_t expected = ReferenceHalf(four[k]);
      const bool nan = (expected & 0x7c00u) == 0x7c00u && (expected & 0x3ffu) != 0;
      const bool same = nan ? (halves[k] & 0x7c00u) == 0x7c00u && (halves[k] & 0x3ffu) != 0
                            : halves[k] == expected;
      if (!same && ++mismatches <= 5) {
        ADD_FAILURE() << four[k] << ": " << std::hex << halves[k] << ", expected " << expected;
      }
    }
  }
  EXPECT_EQ(mismatches, 0) << "of " << values.size();
}

TEST(Simd, StoredHalvesLoadBackWithinTheirRounding) {
  uint16_t stored[4];
  const F4 values = {0.2f, 1234.5f, 3e-6f, 65504.0f};
  StoreHalf4(stored, values);
  const F4 loaded = LoadHalf4(stored);
  for (int k = 0; k < 4; ++k) {
    // Normal halves within 2^-11 relative, subnormal ones (below 2^-14) within 2^-25.
    EXPECT_NEAR(loaded[k], values[k], std::max(std::abs(values[k]) * 0x1p-11f, 0x1p-25f)) << k;
  }
  EXPECT_EQ(loaded[3], 65504.0f);
}

}  // namespace
}  // namespace parallax::simd

#pragma once
// Matching the SIFT features of two photos: every descriptor of one against every descriptor of
// the other, by the rules of colmap's CPU matcher (its default thresholds, Lowe's ratio test and
// a cross check). colmap 3.8 matches through approximate k-d trees rebuilt for each pair, most of
// its matching time (docs/performance.md); this is exact, and a matrix product.
#include <array>
#include <cstdint>
#include <vector>

namespace parallax {

// SIFT descriptors as colmap stores them: `rows` rows of 128 bytes, row-major, each row the
// descriptor normalised to length 512.
struct SiftDescriptors {
  const uint8_t* data = nullptr;
  int rows = 0;
};
constexpr int kSiftDimensions = 128;

struct SiftMatchingThresholds {
  float max_angle = 0.7f;  // Radians between the best descriptors (colmap's max_distance).
  float max_ratio = 0.8f;  // Best angle over second-best angle (Lowe's ratio test).
};

// A pair of feature indices: the first photo's feature, the second photo's.
using FeatureMatch = std::array<uint32_t, 2>;

// The features of `first` and `second` that are each other's nearest descriptor (the largest
// dot product), closer than `max_angle` and clearly closer than their second nearest: the
// matches colmap's matcher keeps, before the geometric verification. In `first`'s order.
std::vector<FeatureMatch> MatchSiftFeatures(const SiftDescriptors& first, const SiftDescriptors& second,
                                            const SiftMatchingThresholds& thresholds = {});

}  // namespace parallax

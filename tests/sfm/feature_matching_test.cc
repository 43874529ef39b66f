#include "sfm/feature_matching.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace parallax {
namespace {

using Descriptors = std::vector<uint8_t>;

// `count` random descriptors as SIFT's bytes: non-negative, length ~512, at most 255.
Descriptors RandomDescriptors(int count, std::mt19937& random) {
  std::gamma_distribution<float> magnitude(0.5f, 1.0f);
  Descriptors descriptors;
  for (int i = 0; i < count; ++i) {
    std::vector<float> values(kSiftDimensions);
    float norm = 0;
    for (float& value : values) {
      value = magnitude(random);
      norm += value * value;
    }
    for (float value : values) {
      descriptors.push_back(static_cast<uint8_t>(std::min(255.0f, std::round(512 * value / std::sqrt(norm)))));
    }
  }
  return descriptors;
}

// `descriptor` with noise of `amount` bytes (standard deviation) added, clamped to bytes.
Descriptors Perturbed(const Descriptors& descriptors, float amount, std::mt19937& random) {
  std::normal_distribution<float> noise(0, amount);
  Descriptors perturbed;
  for (uint8_t value : descriptors) {
    perturbed.push_back(static_cast<uint8_t>(std::clamp(std::round(value + noise(random)), 0.0f, 255.0f)));
  }
  return perturbed;
}

SiftDescriptors View(const Descriptors& descriptors) {
  return {descriptors.data(), static_cast<int>(descriptors.size() / kSiftDimensions)};
}

// The definition, pair by pair in integers: colmap's rules written out plainly.
std::vector<FeatureMatch> ReferenceMatches(const Descriptors& first, const Descriptors& second) {
  const int rows1 = View(first).rows, rows2 = View(second).rows;
  auto dot = [&](int i, int j) {
    int sum = 0;
    for (int k = 0; k < kSiftDimensions; ++k) sum += first[i * kSiftDimensions + k] * second[j * kSiftDimensions + k];
    return sum;
  };
  // The nearest of `i` among `count` others by `score(i, j)`, or -1 where it fails the tests.
  auto nearest = [](int i, int count, auto score) {
    int best = 0, second_best = 0, index = -1;
    for (int j = 0; j < count; ++j) {
      const int value = score(i, j);
      if (value > best) {
        second_best = best;
        best = value;
        index = j;
      } else if (value > second_best) {
        second_best = value;
      }
    }
    const double best_angle = std::acos(std::min(best / (512.0 * 512.0), 1.0));
    const double second_angle = std::acos(std::min(second_best / (512.0 * 512.0), 1.0));
    if (index < 0 || best_angle > 0.7 || best_angle >= 0.8 * second_angle) return -1;
    return index;
  };
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < rows1; ++i) {
    const int j = nearest(i, rows2, dot);
    if (j < 0) continue;
    if (nearest(j, rows1, [&](int a, int b) { return dot(b, a); }) != i) continue;
    matches.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(j)});
  }
  return matches;
}

TEST(FeatureMatching, FindsEachPerturbedDescriptorAndRejectsStrangers) {
  std::mt19937 random(3);
  const Descriptors scene = RandomDescriptors(700, random);
  // The second photo sees the first 500 features again, with noise, in reverse order, and 300
  // features of its own.
  Descriptors second = RandomDescriptors(300, random);
  const Descriptors seen = Perturbed(Descriptors(scene.begin(), scene.begin() + 500 * kSiftDimensions), 4, random);
  for (int i = 499; i >= 0; --i) {
    second.insert(second.end(), seen.begin() + i * kSiftDimensions, seen.begin() + (i + 1) * kSiftDimensions);
  }
  const std::vector<FeatureMatch> matches = MatchSiftFeatures(View(scene), View(second));
  int correct = 0;
  for (const FeatureMatch& match : matches) correct += match[1] == 300 + 499 - match[0];
  EXPECT_EQ(correct, static_cast<int>(matches.size()));
  EXPECT_GE(correct, 490);  // Noise of 4 in 512 leaves almost every one its own nearest.
}

TEST(FeatureMatching, RejectsAmbiguousAndDistantNearest) {
  std::mt19937 random(5);
  const Descriptors first = RandomDescriptors(2, random);
  Descriptors second = first;  // Feature 0 twice (ambiguous), feature 1 once.
  second.insert(second.end(), first.begin(), first.begin() + kSiftDimensions);
  std::vector<FeatureMatch> matches = MatchSiftFeatures(View(first), View(second));
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0], (FeatureMatch{1, 1}));
  // Unrelated descriptors are over 0.7 radians apart: nothing matches.
  EXPECT_TRUE(MatchSiftFeatures(View(first), View(RandomDescriptors(50, random))).empty());
}

// Blocks of rows, vectorised maxima and the branch-free column search give exactly the matches
// of the plain definition, on sizes that fill no block evenly.
TEST(FeatureMatching, AgreesWithTheDefinition) {
  std::mt19937 random(11);
  const Descriptors first = RandomDescriptors(613, random);
  Descriptors second = Perturbed(first, 30, random);
  second.resize(333 * kSiftDimensions);
  const Descriptors extra = RandomDescriptors(200, random);
  second.insert(second.end(), extra.begin(), extra.end());
  const std::vector<FeatureMatch> expected = ReferenceMatches(first, second);
  EXPECT_GT(expected.size(), 100u);
  EXPECT_LT(expected.size(), 333u);  // Noise of 30 loses some: the thresholds are exercised.
  EXPECT_EQ(MatchSiftFeatures(View(first), View(second)), expected);
  EXPECT_TRUE(MatchSiftFeatures(View(first), View(Descriptors())).empty());
}

}  // namespace
}  // namespace parallax

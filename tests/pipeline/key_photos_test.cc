// Key photo selection on verified pairs made up for the purpose: how far apart the keys land
// follows how much neighbours share, not the photo count.
#include "pipeline/key_photos.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace parallax {
namespace {

std::string Name(int i) {
  char name[16];
  std::snprintf(name, sizeof(name), "%04d.png", i);
  return name;
}

struct Capture {
  std::vector<std::string> names;
  std::vector<VerifiedPair> pairs;
  std::map<std::string, int> features;
};

// `count` photos of 1000 features each along a path, every pair up to 19 apart matched, photos
// d apart sharing 1000 * 0.5^(d / halving) features.
Capture Walk(int count, double halving) {
  Capture capture;
  for (int i = 0; i < count; ++i) {
    capture.names.push_back(Name(i));
    capture.features[Name(i)] = 1000;
    for (int d = 1; d <= 19 && i + d < count; ++d) {
      capture.pairs.push_back({Name(i), Name(i + d), static_cast<int>(1000 * std::pow(0.5, d / halving))});
    }
  }
  return capture;
}

TEST(KeyPhotos, DenserCapturesOfTheSameSceneGetKeysAsFarApart) {
  // Sharing halves every 2 photos (100 photos) or every 8 (400 photos over the same path): 30%
  // is kept up to 3 and 13 photos ahead.
  const Capture sparse_capture = Walk(100, 2);
  const std::vector<std::string> sparse =
      KeyPhotos(sparse_capture.names, sparse_capture.pairs, sparse_capture.features, {});
  const Capture dense_capture = Walk(400, 8);
  const std::vector<std::string> dense = KeyPhotos(dense_capture.names, dense_capture.pairs, dense_capture.features, {});
  EXPECT_EQ(sparse.size(), 34u);  // 0, 3, ..., 99.
  EXPECT_EQ(dense.size(), 32u);   // 0, 13, ..., 390, then 399.
  EXPECT_EQ(dense[1], Name(13));
  EXPECT_EQ(dense.front(), Name(0));
}

TEST(KeyPhotos, EveryPhotoIsAKeyWhereNeighboursShareTooLittle) {
  const Capture capture = Walk(30, 0.5);  // 25% shared with the next photo.
  EXPECT_EQ(KeyPhotos(capture.names, capture.pairs, capture.features, {}), capture.names);
  Capture unmatched = capture;
  unmatched.pairs.clear();
  EXPECT_EQ(KeyPhotos(unmatched.names, unmatched.pairs, unmatched.features, {}), capture.names);
}

TEST(KeyPhotos, TheNextKeyStaysInsideTheWindow) {
  const Capture capture = Walk(60, 100);  // Nearly identical photos.
  KeyPhotoOptions options;
  options.window = 5;
  const std::vector<std::string> keys = KeyPhotos(capture.names, capture.pairs, capture.features, options);
  ASSERT_EQ(keys.size(), 13u);  // 0, 5, ..., 55, 59.
  EXPECT_EQ(keys[1], Name(5));
  EXPECT_EQ(keys.back(), Name(59));
}

}  // namespace
}  // namespace parallax

#pragma once
// Estimates each photo's exposure and white balance from the colors its sparse points have
// in the photos that see them (core/color_gains.h).
#include <filesystem>
#include <string>

#include "core/color_gains.h"
#include "core/sparse_model.h"

namespace parallax {

struct ColorGainsOptions {
  // A photo needs this many usable observations (neither too dark nor clipped) to get a gain;
  // with fewer it keeps 1.
  int min_observations = 30;
  // Gains are clamped to [1 / max_gain, max_gain].
  float max_gain = 8;
  void Check() const;
};

struct ColorGainsEstimate {
  ColorGains gains;
  int photos_without_gain = 0;  // Too few usable observations: gain 1.
  std::string note;             // What was estimated, for the report.
};

// Model: a point's linear color in photo i is gain_i^-1 times the point's own color, per
// channel. Solved in log space by alternating medians (robust to speculars, occlusions and
// mismatches), gains normalised to a geometric mean of 1 over the photos, so the common
// exposure is the set's typical one. Each observation is the mean of the 5x5 pixels around
// the keypoint. Reads `images_dir`/<name> (sRGB) one photo at a time. Throws BadInputError
// naming an unreadable photo.
ColorGainsEstimate EstimateColorGains(const SparseModel& model, const std::filesystem::path& images_dir,
                                      const ColorGainsOptions& options = {});

}  // namespace parallax

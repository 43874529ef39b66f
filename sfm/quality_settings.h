#pragma once
// What each --quality asks of colmap's feature extraction and matching: the workspace's photos
// are extracted with it, and so are photos registered into its model later.
#include "core/quality.h"

namespace parallax {

struct QualitySettings {
  int max_image_size;    // Long side in pixels the extractor scales the photos down to.
  int max_num_features;  // Features kept per photo.
  bool guided_matching;
};
QualitySettings SettingsFor(Quality quality);

}  // namespace parallax

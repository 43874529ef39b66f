#pragma once
// Many pairs of photos matched by sfm/feature_matching.h, on all cores.
#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "sfm/feature_matching.h"

namespace parallax {

// Each of `pairs` (indices into `images`) matched by MatchSiftFeatures, in `pairs`' order; the
// pairs on all cores, 16 at a time, and `done(n)` told from the calling thread after each 16.
std::vector<std::vector<FeatureMatch>> MatchSiftPairs(const std::vector<SiftDescriptors>& images,
                                                      const std::vector<std::array<size_t, 2>>& pairs,
                                                      const std::function<void(size_t done)>& done = {});

}  // namespace parallax

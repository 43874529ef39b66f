#include "sfm/pair_matching.h"

#include <algorithm>

#include <tbb/parallel_for.h>

namespace parallax {

std::vector<std::vector<FeatureMatch>> MatchSiftPairs(const std::vector<SiftDescriptors>& images,
                                                      const std::vector<std::array<size_t, 2>>& pairs,
                                                      const std::function<void(size_t done)>& done) {
  std::vector<std::vector<FeatureMatch>> matches(pairs.size());
  for (size_t start = 0; start < pairs.size(); start += 16) {
    const size_t end = std::min(pairs.size(), start + 16);
    tbb::parallel_for(start, end, [&](size_t p) {
      matches[p] = MatchSiftFeatures(images[pairs[p][0]], images[pairs[p][1]]);
    });
    if (done) done(end);
  }
  return matches;
}

}  // namespace parallax

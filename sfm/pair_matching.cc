#include "sfm/pair_matching.h"

#include <algorithm>
#include <map>

#include <tbb/parallel_for.h>

#include "colmap/database.h"
#include "sfm/feature_matching.h"

namespace parallax {

void MatchAndStorePairs(const std::filesystem::path& database, const std::vector<std::array<uint32_t, 2>>& pairs,
                        const std::function<void(size_t done)>& done) {
  const std::vector<DatabaseDescriptors> images = ReadDescriptors(database);
  std::map<uint32_t, SiftDescriptors> descriptors;  // By image id.
  for (const DatabaseDescriptors& image : images) descriptors[image.image_id] = {image.data.data(), image.rows};
  std::vector<RawMatches> matches;
  for (const auto& [first, second] : pairs) matches.push_back({first, second, {}});
  for (size_t start = 0; start < pairs.size(); start += 16) {
    const size_t end = std::min(pairs.size(), start + 16);
    tbb::parallel_for(start, end, [&](size_t p) {
      matches[p].matches = MatchSiftFeatures(descriptors.at(pairs[p][0]), descriptors.at(pairs[p][1]));
    });
    if (done) done(end);
  }
  WriteRawMatches(database, matches);
}

}  // namespace parallax

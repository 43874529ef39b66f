#include "pipeline/key_photos.h"

#include <algorithm>
#include <utility>

namespace parallax {

std::vector<std::string> KeyPhotos(const std::vector<std::string>& names, const std::vector<VerifiedPair>& pairs,
                                   const std::map<std::string, int>& features, const KeyPhotoOptions& options) {
  std::map<std::pair<std::string, std::string>, int> shared;
  for (const VerifiedPair& pair : pairs) shared[std::minmax(pair.first, pair.second)] = pair.inliers;
  auto shares_enough = [&](const std::string& a, const std::string& b) {
    const auto found = shared.find(std::minmax(a, b));
    const auto features_a = features.find(a), features_b = features.find(b);
    if (found == shared.end() || features_a == features.end() || features_b == features.end()) return false;
    return found->second >= options.min_shared * std::min(features_a->second, features_b->second);
  };
  std::vector<std::string> keys;
  for (size_t key = 0; key < names.size();) {
    keys.push_back(names[key]);
    size_t next = key + 1;
    const size_t last = std::min(names.size() - 1, key + static_cast<size_t>(options.window));
    for (size_t candidate = last; candidate > key + 1; --candidate) {
      if (shares_enough(names[key], names[candidate])) {
        next = candidate;
        break;
      }
    }
    key = next;
  }
  return keys;
}

}  // namespace parallax

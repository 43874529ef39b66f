#pragma once
// Key photos of a dense ordered capture (docs/scale.md, "Key photos"): the photos the
// incremental mapper grows its model from when neighbours in name order see nearly the same
// thing. The other photos are registered to the key photos' model afterwards, so the mapper's
// memory and time follow the scene, not the number of photos taken of it.
#include <map>
#include <string>
#include <vector>

#include "colmap/database.h"

namespace parallax {

struct KeyPhotoOptions {
  // How far ahead in name order the next key may be (the matcher's window: pairs further
  // apart are not matched by the sequential matcher, so their counts mean nothing).
  int window = 19;
  // Consecutive keys share at least this share of the features of the one with fewer, in
  // verified matches.
  double min_shared = 0.3;
};

// `names` in capture (name) order; `features`: each photo's feature count. From each key, the
// next key is the farthest photo within the window that shares enough with it; the photo right
// after it where none does. The first photo is a key. Every photo is a key when consecutive
// photos share too little (a sparse capture, or one not in name order).
std::vector<std::string> KeyPhotos(const std::vector<std::string>& names, const std::vector<VerifiedPair>& pairs,
                                   const std::map<std::string, int>& features, const KeyPhotoOptions& options);

}  // namespace parallax

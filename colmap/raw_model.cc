#include "colmap/raw_model.h"

#include <algorithm>
#include <map>
#include <utility>

#include "colmap/database.h"
#include "core/error.h"

namespace parallax {
namespace fs = std::filesystem;

std::vector<std::string> FixedIntrinsicsArguments() {
  return {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
          "--Mapper.ba_refine_extra_params", "0"};
}

std::string NoInitialPairReason(const fs::path& database, int num_images) {
  const std::vector<VerifiedPair> pairs = ReadVerifiedPairs(database);
  if (pairs.empty()) {
    return "the photos share no features: no two of the " + std::to_string(num_images) +
           " photos have enough matching features to pass geometric verification (different "
           "scenes, too little texture or too little overlap)";
  }
  const bool no_parallax = std::all_of(pairs.begin(), pairs.end(), [](const VerifiedPair& pair) {
    return pair.geometry == PairGeometry::kPlanarOrPanoramic || pair.geometry == PairGeometry::kPanoramic;
  });
  if (!no_parallax) return "";
  const VerifiedPair& best = *std::max_element(
      pairs.begin(), pairs.end(), [](const VerifiedPair& a, const VerifiedPair& b) { return a.inliers < b.inliers; });
  return "the photos have no parallax: each of the " + std::to_string(pairs.size()) +
         " matched pairs is explained by a homography (the best, " + best.first + " and " + best.second +
         ", by " + std::to_string(best.inliers) + " matches), as for near-identical photos or photos "
         "taken from one spot; take the photos from positions a step or more apart";
}

SparseModel LargestModel(const std::vector<fs::path>& dirs) {
  SparseModel best;
  for (const fs::path& dir : dirs) {
    SparseModel model = ReadSparseModel(dir);
    if (model.Images().size() > best.Images().size()) best = std::move(model);
  }
  return best;
}

SparseModel AlignKnownModelToDatabase(const SparseModel& known, const std::vector<std::string>& names,
                                      const fs::path& known_dir, const fs::path& database) {
  const std::map<std::string, DatabaseImage> ids = ReadDatabaseImages(database);
  const bool single = known.Cameras().size() == 1;
  SparseModel aligned;
  for (const std::string& name : names) {
    const SparseImage* image = known.FindImageByName(name);
    if (!image) {
      throw BadInputError("--known-cameras " + known_dir.string() + " has no image named " + name);
    }
    const auto id = ids.find(name);
    if (id == ids.end()) {
      throw BadInputError(database.string() + " has no image named " + name);
    }
    SparseImage copy = *image;
    copy.id = id->second.image_id;
    copy.camera_id = id->second.camera_id;
    copy.points2d.clear();
    // One shared camera in the database when the known model has one (single_camera).
    if (!(single && !aligned.Cameras().empty())) {
      Camera camera = known.CameraById(image->camera_id);
      camera.id = copy.camera_id;
      aligned.AddCamera(camera);
    }
    aligned.AddImage(std::move(copy));
  }
  return aligned;
}

}  // namespace parallax

#pragma once
// colmap's raw (distorted) models: the mapper options that fix the intrinsics, why the mapper
// found no pair to start from, the largest of the models it wrote, and a known model renumbered
// as colmap's database numbers its photos. What runs on a workspace's raw model is
// pipeline/raw_model_workspace.h's.
#include <filesystem>
#include <string>
#include <vector>

#include "core/sparse_model.h"

namespace parallax {

// The mapper options that hold every camera's intrinsics fixed in its bundle adjustments.
std::vector<std::string> FixedIntrinsicsArguments();

// Why the mapper found no pair of photos to start from, where the verified matches in
// `database` show it: no pair at all, or only pairs one homography explains (photos from one
// spot, near-identical copies). "" when the matches do not explain it.
std::string NoInitialPairReason(const std::filesystem::path& database, int num_images);

// The model with the most registered images among `dirs` (the first of equals).
SparseModel LargestModel(const std::vector<std::filesystem::path>& dirs);

// The known model rewritten with the ids colmap's database gave the photos `names`, so that
// point_triangulator can match its images and cameras to the features and matches; without
// keypoints, and with one shared camera when the known model has one. Throws BadInputError when
// the known model (read from `known_dir`) or the database lacks one of the photos.
SparseModel AlignKnownModelToDatabase(const SparseModel& known, const std::vector<std::string>& names,
                                      const std::filesystem::path& known_dir,
                                      const std::filesystem::path& database);

}  // namespace parallax

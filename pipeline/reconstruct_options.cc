#include "pipeline/reconstruct_options.h"

#include <cmath>

#include "core/check.h"
#include "core/error.h"

namespace parallax {

void ReconstructOptions::Check() const {
  if (!intrinsics.empty() && intrinsics.size() != 1 && intrinsics.size() != 4) {
    throw UsageError("intrinsics must be f or fx,fy,cx,cy");
  }
  for (const double value : intrinsics) {
    if (!(value > 0) || !std::isfinite(value)) throw UsageError("intrinsics must be positive numbers");
  }
  if (!intrinsics.empty() && !known_cameras.empty()) {
    throw UsageError("intrinsics and known_cameras exclude each other");
  }
  if (!IsProjectionSupported(camera_model)) {
    throw UsageError("camera_model " + std::string(CameraModelName(camera_model)) + " is not supported");
  }
  RequireOption(exhaustive_limit >= 2, "ReconstructOptions.exhaustive_limit", exhaustive_limit, ">= 2");
  RequireOption(hierarchical_limit >= 2, "ReconstructOptions.hierarchical_limit", hierarchical_limit, ">= 2");
  RequireOption(hierarchical_cluster_images >= 10, "ReconstructOptions.hierarchical_cluster_images",
                hierarchical_cluster_images, ">= 10");
  RequireOption(key_photo_shared > 0 && key_photo_shared <= 1, "ReconstructOptions.key_photo_shared",
                key_photo_shared, "(0, 1]");
  RequireOption(sequential_overlap >= 2, "ReconstructOptions.sequential_overlap", sequential_overlap, ">= 2");
  RequireOption(retrieval_images >= 1, "ReconstructOptions.retrieval_images", retrieval_images, ">= 1");
  RequireOption(ordered_share > 0 && ordered_share <= 1, "ReconstructOptions.ordered_share", ordered_share,
                "in (0, 1]");
  RequireOption(refine_principal_point_min_images >= 1, "ReconstructOptions.refine_principal_point_min_images",
                refine_principal_point_min_images, ">= 1");
  RequireOption(max_refined_principal_point_offset > 0, "ReconstructOptions.max_refined_principal_point_offset",
                max_refined_principal_point_offset, "> 0");
  RequireOption(min_principal_point_prediction_gain >= 0 && min_principal_point_prediction_gain < 1,
                "ReconstructOptions.min_principal_point_prediction_gain", min_principal_point_prediction_gain,
                "in [0, 1)");
  RequireOption(min_principal_point_deviations > 0, "ReconstructOptions.min_principal_point_deviations",
                min_principal_point_deviations, "> 0");
  RequireOption(max_retriangulations >= 0, "ReconstructOptions.max_retriangulations", max_retriangulations, ">= 0");
  RequireOption(mvs_sources >= 0, "ReconstructOptions.mvs_sources", mvs_sources, ">= 0");
  RequireOption(mvs_scale == 0 || (mvs_scale >= 0.25 && mvs_scale <= 1), "ReconstructOptions.mvs_scale",
                mvs_scale, "0 (as quality says) or [0.25, 1]");
  RequireOption(mvs_max_size == 0 || mvs_max_size >= 64, "ReconstructOptions.mvs_max_size", mvs_max_size,
                "0 (as quality says) or >= 64");
  if (mvs_scale > 0 && mvs_max_size > 0) {
    throw UsageError("mvs_scale and mvs_max_size exclude each other");
  }
  plausibility.Check();
}

}  // namespace parallax

#pragma once
// Is a reconstruction COLMAP called a success believable? COLMAP registers every image of a
// tiny-baseline capture at 0.1 px reprojection error with a focal length 3x wrong
// (DESIGN.md, measured pitfalls): registration count and reprojection error do not show it.
// These checks look at what does: the focal length against its prior, and how well the
// points are triangulated.
#include <string>
#include <vector>

#include "core/sparse_model.h"

namespace parallax {

struct PlausibilityOptions {
  // Estimated/prior focal ratio allowed when the prior comes from EXIF.
  double max_focal_ratio_exif = 1.3;
  // Ratio allowed when the prior is COLMAP's default 1.2 * max(w, h): [1/3, 2] spans
  // horizontal fields of view from about 100 down to 24 degrees.
  double max_focal_ratio_default = 2.0;
  double min_focal_ratio_default = 1.0 / 3.0;
  // A point is well triangulated when two of its rays meet at least at this angle (degrees).
  double well_triangulated_deg = 2.0;
  // Below this median triangulation angle (degrees) depth and focal length are ill-determined.
  double min_median_triangulation_deg = 2.0;
  // The principal point may lie at most this fraction of the image size from its centre.
  double max_principal_point_offset = 0.1;
  // An image is well constrained with at least this many well-triangulated points ...
  int min_points_per_image = 30;
  // ... and at least this share of registered images must be.
  double min_well_constrained_share = 0.8;
  void Check() const;
};

struct PlausibilityReport {
  double focal_px = 0;          // Mean estimated focal length (fx, fy averaged).
  double focal_prior_px = 0;    // What SfM started from.
  bool prior_from_exif = false;
  double median_triangulation_deg = 0;
  double well_constrained_image_share = 0;
  std::vector<std::string> problems;  // Empty when plausible; each names what is off.

  bool Plausible() const { return problems.empty(); }
};

// `focal_prior_px` and `prior_from_exif` describe the prior of the model's cameras.
PlausibilityReport CheckPlausibility(const SparseModel& model, double focal_prior_px,
                                     bool prior_from_exif,
                                     const PlausibilityOptions& options = {});

// How far the principal point lies from the image centre, as the larger of its x and y
// offsets divided by the image width and height (0 = centred, 0.5 = on the border).
double PrincipalPointOffset(const Camera& camera);

// Largest angle (degrees) between the rays from the observing cameras to each 3D point, in
// the order of model.Points3D(). Long tracks use their first 16 observations.
std::vector<double> TriangulationAnglesDeg(const SparseModel& model);

}  // namespace parallax

#pragma once
// Is a reconstruction COLMAP called a success believable? COLMAP registers every image of a
// tiny-baseline capture at 0.1 px reprojection error with a focal length 3x wrong
// (docs/design.md, measured pitfalls): registration count and reprojection error do not show it.
// These checks look at what does: the focal length against its prior, whether the photos
// determine the focal length at all, and how well the points are triangulated.
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
  // The photos must determine the focal length: re-solved with the focal length held at
  // `focal_test_factor` times and at 1/`focal_test_factor` times the estimate (poses, points
  // and distortion free), the model must fit at least `min_focal_rms_ratio` times worse (RMS
  // reprojection error) both ways. Cameras that translate without rotating (a slider, a tiny
  // baseline) fit any focal length equally well, and COLMAP keeps whatever it drifted to.
  // Checked when the prior is not from EXIF (against EXIF the focal ratio check suffices).
  double focal_test_factor = 2;
  double min_focal_rms_ratio = 1.5;
  // Points (evenly sampled) used by that test: bounds its cost on large models.
  int focal_test_max_points = 2000;
  void Check() const;
};

struct PlausibilityReport {
  double focal_px = 0;          // Mean estimated focal length (fx, fy averaged).
  double focal_prior_px = 0;    // What SfM started from.
  bool prior_from_exif = false;
  double median_triangulation_deg = 0;
  double well_constrained_image_share = 0;
  // RMS reprojection error with the focal length held at the better of focal_test_factor
  // times or 1/focal_test_factor times the estimate, over the RMS at the estimate; 0 when not
  // tested.
  double focal_rms_ratio = 0;
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

// How far the photos pin the focal length down. Every camera's focal length is held at
// `factor` times its estimate and the model re-solved (poses, points and distortion free,
// principal point held), starting from the exact ambiguity of cameras that only translate
// (lateral coordinates divided by `factor`, depth kept). Returns the RMS reprojection error
// after over the RMS before, both over the same points: about 1 when the focal length is not
// determined. Uses at most `max_points` points (evenly sampled, two or more observations).
// 0 when it cannot be measured (no such points, a model without projection).
double FocalRmsRatio(const SparseModel& model, double factor, int max_points);

// Largest angle (degrees) between the rays from the observing cameras to each 3D point, in
// the order of model.Points3D(). Long tracks use their first 16 observations.
std::vector<double> TriangulationAnglesDeg(const SparseModel& model);

}  // namespace parallax

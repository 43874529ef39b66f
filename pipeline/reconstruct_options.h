#pragma once
// What `parallax reconstruct` is asked for (ReconstructOptions), shared by the stages that
// carry it out (pipeline/sfm_stages.h, dense_stages.h, slurm.h) and their policy.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/quality.h"
#include "mesh/poisson.h"
#include "sfm/plausibility.h"

namespace parallax {

// SfM at each Quality: fast: images up to 1024 px, 2048 features; balanced: 2000 px, 4096
// features; best: 3200 px, 8192 features and guided matching.

// How photos are paired for feature matching. Sequential and retrieval use a vocabulary tree
// that parallax builds from the photos' own features (no tree file is needed), or the one
// ReconstructOptions::vocab_tree names.
enum class MatcherChoice {
  kAuto,        // Exhaustive up to `exhaustive_limit` images; past it, sequential when photos
                // consecutive in name order match each other (an ordered capture), else retrieval.
  kExhaustive,  // Every pair.
  kSequential,  // Neighbours in name order, loops closed by retrieval every few images.
  kRetrieval,   // Each image with the images most similar to it in the vocabulary tree.
};

// How the registered model is grown from the matches.
enum class MapperChoice {
  kAuto,          // Past `exhaustive_limit` images, key photos where the capture is dense and
                  // ordered; else incremental up to `hierarchical_limit` images, hierarchical past it.
  kIncremental,   // COLMAP's mapper: one model, image by image, bundle adjusted as it grows.
  kHierarchical,  // COLMAP's hierarchical_mapper: overlapping clusters of the match graph
                  // mapped apart, then merged.
  kKeyPhotos,     // COLMAP's mapper on the key photos (pipeline/key_photos.h), the others then
                  // registered to their model.
};

enum class StereoMethod { kPatchMatch, kSgbm };

struct ReconstructOptions {
  Quality quality = Quality::kBalanced;
  MatcherChoice matcher = MatcherChoice::kAuto;
  // Single-focal by default: free fx/fy drift on rings of cameras (docs/design.md pitfalls).
  CameraModel camera_model = CameraModel::kSimpleRadial;
  // Known intrinsics, held fixed in bundle adjustment: {f} (principal point at the image
  // centre) or {fx, fy, cx, cy}. Empty: estimated.
  std::vector<double> intrinsics;
  // A COLMAP model whose intrinsics and poses are used as they are (SfM only triangulates).
  std::filesystem::path known_cameras;
  // An implausible reconstruction is an error (exit 2) instead of a warning.
  bool strict = false;
  // Plan only: say which stages would run or be skipped, and why.
  bool dry_run = false;
  // colmap executable (name on PATH or path).
  std::string colmap = "colmap";
  // Above this many images the automatic matcher is sequential or retrieval (docs/scale.md:
  // where exhaustive matching starts to cost more than they do, measured).
  int exhaustive_limit = 75;
  MapperChoice mapper = MapperChoice::kAuto;
  // Above this many images the automatic mapper is hierarchical (docs/scale.md: where the
  // incremental mapper's bundle adjustments start to cost more, measured).
  int hierarchical_limit = 800;
  // Most images in one of the hierarchical mapper's clusters.
  int hierarchical_cluster_images = 100;
  // Consecutive key photos share at least this share of their features in verified matches
  // (docs/scale.md: the plaza's neighbours 7 degrees apart share 33%).
  double key_photo_shared = 0.3;
  // colmap's SequentialMatching.overlap: each image is matched with the next overlap - 1
  // images in name order (and those a power of two ahead).
  int sequential_overlap = 20;
  // Most similar images each image is matched with by retrieval.
  int retrieval_images = 40;
  // Share of consecutive photos (name order) that must match for the automatic matcher to
  // treat the capture as ordered.
  double ordered_share = 0.8;
  // A vocabulary tree file (colmap's format: one vocab_tree_builder wrote, or one of COLMAP's
  // pre-built trees) for sequential and retrieval matching, used instead of building one from
  // the photos. Empty: built. Unused by exhaustive matching.
  std::filesystem::path vocab_tree;
  // A camera shared by at least this many photos gets its principal point refined in a final
  // bundle adjustment (COLMAP keeps it at the image centre, which skews the rotations of
  // photos whose principal point is off-centre).
  int refine_principal_point_min_images = 5;
  // The refinement is kept only if the principal point stays within this fraction of the
  // image size from the centre; further off it was not observable and drifted.
  double max_refined_principal_point_offset = 0.05;
  // ... and if it predicts photos left out of the adjustment better than the centre does: by
  // at least this share of their reprojection error, or by less where it lies at least
  // `min_principal_point_deviations` standard deviations (the jackknife's over the photos) off
  // the centre (docs/cameras.md, "The principal point by prediction").
  double min_principal_point_prediction_gain = 0.003;
  double min_principal_point_deviations = 3;
  // After the final adjustments, the tracks are built afresh from the verified matches with
  // the adjusted cameras, filtered and adjusted again, until the cameras settle or for at most
  // this many rounds (0: the mapper's tracks are kept; docs/cameras.md, "Tracks built afresh").
  int max_retriangulations = 10;
  // Photos held out of everything after structure from motion, as novel-view benchmarks hold
  // them out: registered with the others, then kept out of the depth stage, fusion, the mesh,
  // the color gains and the render sources, and written to Workspace::HeldOut for `evaluate`
  // to render at their cameras and compare. Every n-th photo in name order from the first
  // (0: none), and the photos named.
  int hold_out_every = 0;
  std::vector<std::string> hold_out_photos;
  PlausibilityOptions plausibility;
  // Run multi-view stereo after SfM (the depth stage, pipeline/dense_stages.h), at `quality`.
  bool estimate_depth = true;
  // Depth-stage method: parallax's PatchMatch, or OpenCV's StereoSGBM on rectified pairs (the
  // baseline the bench compares with).
  StereoMethod stereo = StereoMethod::kPatchMatch;
  // Source views per depth map; 0 = as `quality` says.
  int mvs_sources = 0;
  // Resolution of the depth estimate: 0 for `quality`'s long-side cap (MaxImageSizeFor), or a
  // share of each photo side (MvsOptions::image_scale, no cap), or a long-side cap in pixels.
  // At most one of the two is set.
  double mvs_scale = 0;
  int mvs_max_size = 0;
  // Seeds PatchMatch's random search: each view's seed is its image id plus this. Runs with
  // other seeds measure the run-to-run spread of the depth and of what is built from it.
  uint32_t mvs_seed = 0;
  // After depth: Poisson mesh, trimmed and textured (the mesh stage, pipeline/dense_stages.h).
  bool build_mesh = true;
  // What makes the mesh's surface: Poisson over the fused cloud, or the depth maps fused into
  // a signed-distance volume (mesh/poisson.h), with its voxel in depth-map pixels and the maps'
  // weight a cell needs (0: MeshOptions' defaults).
  Mesher mesher = Mesher::kPoisson;
  double tsdf_voxel_pixels = 0;
  double tsdf_min_weight = 0;
  void Check() const;  // Throws UsageError naming the field.
};

}  // namespace parallax

#pragma once
// The structure-from-motion stages of `reconstruct` as data (pipeline/stage_graph.h):
// features, matches, mapper (or triangulate, with known cameras) and undistort, each keyed by
// the one before it. Their decisions are pipeline/sfm_policy.h's; the colmap commands on the
// mapper's models are pipeline/raw_model_workspace.h's.
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "pipeline/reconstruct_options.h"
#include "pipeline/sfm_policy.h"
#include "pipeline/stage_graph.h"
#include "sfm/photo_set.h"

namespace parallax {

// The folder COLMAP and the undistortion read the photos from: the user's, or the
// workspace's copy with the converted photos when some need it (PhotosStage).
std::filesystem::path ReadablePhotosDir(const std::filesystem::path& photos_dir,
                                        const PhotoSet& photos, const Workspace& workspace);

// Writes the workspace's readable copy of the photos: each photo that needs it converted,
// the others linked (or copied where links cannot be made). Not needed, and skipped, when
// every photo is readable as it is.
Stage PhotosStage(const std::filesystem::path& photos_dir, const PhotoSet& photos,
                  const Workspace& workspace, Progress& progress);

// What every SfM stage reads.
struct SfmContext {
  std::filesystem::path photos_dir;  // ReadablePhotosDir.
  const PhotoSet& photos;
  const SparseModel* known;  // --known-cameras, or null.
  const ReconstructOptions& options;
  const Colmap& colmap;
  Workspace workspace;
  CameraSetup camera;
  // MatcherFor: kAuto only past the exhaustive limit, where the capture's order decides.
  MatcherChoice matcher;
  Progress& progress;
  std::set<std::string> held_out;  // HeldOutPhotos.
};

// The plan for the photos of `sfm`. Key photos are chosen from the verified matches, so they
// are decided only once the database exists (a dry run before matching says so); with
// --known-cameras there is nothing to map, only points to triangulate.
MapperPlan PlanMapper(const SfmContext& sfm);

// `photos_key` is PhotosStage's key.
Stage FeaturesStage(const SfmContext& sfm, const std::string& photos_key);
// The vocabulary tree sequential and retrieval matching need, built from the photos' own
// features by colmap vocab_tree_builder; not needed for exhaustive matching, nor with
// ReconstructOptions::vocab_tree, whose content its key then hashes (the matches stage's key
// chains it).
Stage VocabularyTreeStage(const SfmContext& sfm, const std::string& features_key);
Stage MatchesStage(const SfmContext& sfm, const std::string& features_key,
                   const std::string& vocabulary_tree_key);
// Notes the mapper's decisions (a principal-point refinement kept or rejected) in `notes`.
Stage MapperStage(const SfmContext& sfm, const MapperPlan& plan, const std::string& matches_key,
                  std::vector<std::string>& notes);
// Undistortion into the workspace layout (PINHOLE photos and model). `raw_model` is the
// mapper's model, or null in a dry run (the stage is then only planned).
Stage UndistortStage(const SfmContext& sfm, const std::string& mapper_key,
                     const SparseModel* raw_model);

// The mapper's models besides the largest (the one kept). Throws BadInputError when the
// mapper made none.
int OtherModelCount(const Workspace& workspace);

}  // namespace parallax

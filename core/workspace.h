#pragma once
// The layout of a workspace, the folder `reconstruct` writes and `render`, `evaluate` and
// `view` read (docs/design.md "Workspace"). Every path inside a workspace comes from here.
#include <filesystem>
#include <string>

#include "core/scene_folder.h"

namespace parallax {

// What a COLMAP dense map was computed from: photometric consistency only, or also the
// neighbours' geometry.
enum class StereoPass { kPhotometric, kGeometric };

class Workspace {
 public:
  explicit Workspace(std::filesystem::path root) : root_(std::move(root)) {}

  const std::filesystem::path& Root() const { return root_; }

  // The undistorted PINHOLE model and photos, in COLMAP's dense-workspace layout.
  std::filesystem::path Sparse() const { return root_ / "sparse"; }
  std::filesystem::path Images() const { return root_ / "images"; }
  std::filesystem::path Image(const std::string& name) const { return Images() / name; }
  // COLMAP's dense format: stereo/depth_maps/<photo>.<pass>.bin, stereo/normal_maps/...
  std::filesystem::path Stereo() const { return root_ / "stereo"; }
  std::filesystem::path StereoDepthMaps() const { return Stereo() / "depth_maps"; }
  std::filesystem::path StereoNormalMaps() const { return Stereo() / "normal_maps"; }
  std::filesystem::path StereoConsistencyGraphs() const { return Stereo() / "consistency_graphs"; }
  std::filesystem::path StereoDepthMap(const std::string& photo, StereoPass pass) const;
  std::filesystem::path StereoNormalMap(const std::string& photo, StereoPass pass) const;
  std::filesystem::path StereoConfig(const std::string& file) const { return Stereo() / file; }
  // The depth stage's photometric estimates at the working resolution, between its two
  // passes (removed when the stage ends): stereo/estimates/<photo>.bin.
  std::filesystem::path StereoEstimates() const { return Stereo() / "estimates"; }
  std::filesystem::path StereoEstimate(const std::string& photo) const {
    return StereoEstimates() / (photo + ".bin");
  }
  // A view's report once its geometric pass wrote its depth maps: stereo/estimates/<photo>.json.
  std::filesystem::path StereoViewReport(const std::string& photo) const {
    return StereoEstimates() / (photo + ".json");
  }

  // The photos held out of everything after structure from motion (reconstruct --hold-out),
  // laid out as a workspace of their own: held_out/images and held_out/sparse (their cameras
  // and poses in the workspace's frame, without points), for `evaluate` to render and compare.
  Workspace HeldOut() const { return Workspace(root_ / "held_out"); }

  // Structure from motion's own files: the COLMAP database, the raw (distorted) models.
  std::filesystem::path Sfm() const { return root_ / "sfm"; }
  std::filesystem::path Database() const { return Sfm() / "database.db"; }
  std::filesystem::path ImageList() const { return Sfm() / "image_list.txt"; }
  // The key photos the mapper starts from in a dense ordered capture (pipeline/key_photos.h).
  std::filesystem::path KeyPhotoList() const { return Sfm() / "key_photos.txt"; }
  // The photos as COLMAP reads them, when some had to be converted (sfm/photo_conversion.h).
  std::filesystem::path ReadablePhotos() const { return Sfm() / "photos"; }
  std::filesystem::path KnownModel() const { return Sfm() / "known"; }
  std::filesystem::path Models() const { return Sfm() / "models"; }
  std::filesystem::path RawModel() const { return Sfm() / "sparse"; }
  std::filesystem::path MatchedMarker() const { return Sfm() / "matched"; }
  std::filesystem::path VocabularyTree() const { return Sfm() / "vocab_tree.bin"; }
  std::filesystem::path RefinedModelScratch() const { return Sfm() / "refined.tmp"; }
  // A part of the raw model adjusted apart (the principal point's check, pipeline/sfm_policy.h).
  std::filesystem::path PartialModelScratch() const { return Sfm() / "partial.tmp"; }
  // The cameras' uncertainty that check measured (pipeline/camera_uncertainty.h), where it ran.
  std::filesystem::path CameraUncertainty() const { return Sfm() / "camera_uncertainty.json"; }

  // Depth maps at the depth stage's working size (ReadDepthExrAt reads them at the photo's):
  // depth/<stem>.exr and depth/<stem>.confidence.exr.
  std::filesystem::path DepthDir() const { return root_ / "depth"; }
  std::filesystem::path Depth(const std::string& photo) const;
  std::filesystem::path DepthConfidence(const std::string& photo) const;
  std::filesystem::path DepthViews() const { return DepthDir() / "views.json"; }

  // Per-photo exposure and white balance correction (core/color_gains.h).
  std::filesystem::path ColorGainsFile() const { return root_ / "color_gains.json"; }

  std::filesystem::path Fused() const { return root_ / "fused.ply"; }
  std::filesystem::path PoissonMesh() const { return root_ / "mesh_poisson.ply"; }
  std::filesystem::path PoissonMeshScratch() const { return root_ / "mesh_poisson.tmp.ply"; }
  // The textured mesh (mesh.obj, mesh.mtl, mesh.png) and the viewer's simplified copy.
  std::filesystem::path MeshDir() const { return root_ / "mesh"; }
  std::filesystem::path Mesh() const { return MeshDir() / "mesh.obj"; }
  std::filesystem::path MeshSummary() const { return MeshDir() / "summary.json"; }
  std::filesystem::path DisplayMeshDir() const { return root_ / "mesh_display"; }
  std::filesystem::path DisplayMesh() const { return DisplayMeshDir() / "mesh.obj"; }
  // The mesh and the cloud the scene frame is fitted to and `view` shows.
  SceneFiles Geometry() const { return {Mesh(), Fused()}; }
  // The source views: the undistorted photos, their cameras, depth maps and color gains.
  ViewSetPaths Sources() const;

  std::filesystem::path Logs() const { return root_ / "logs"; }
  std::filesystem::path Log(const std::string& stage) const { return Logs() / (stage + ".log"); }
  std::filesystem::path Report() const { return root_ / "report.json"; }
  std::filesystem::path Stages() const { return root_ / "stages.json"; }
  // Scratch folders of a stage that replaces its outputs whole.
  std::filesystem::path UndistortScratch() const { return root_ / ".undistort.tmp"; }
  std::filesystem::path WriteProbe() const { return root_ / ".parallax_write_test"; }

 private:
  std::filesystem::path root_;
};

// The source views of a workspace (<ws>/sparse, images, depth and color gains; depth maps may
// still be missing) or of a scene folder (its training set). Throws BadInputError naming the
// folder when it is neither.
ViewSetPaths SourcePathsFor(const std::filesystem::path& workspace_or_scene);

}  // namespace parallax

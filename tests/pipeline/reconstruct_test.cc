// End to end through the real colmap on example_images/small.
#include "pipeline/reconstruct.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imagebuf.h>

#include "core/atomic_file.h"
#include "core/color_gains.h"
#include "core/depth_map.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "eval/cloud_evaluation.h"
#include "colmap/runner.h"
#include "mvs/fusion.h"
#include "eval/mesh_evaluation.h"
#include "mvs/mvs.h"
#include "geometry/ply.h"
#include "eval/register_held_out.h"
#include "mvs/sgbm.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/fusion_workspace.h"
#include "pipeline/mesh_workspace.h"
#include "geometry/obj.h"
#include "tests/cli_runner.h"
#include "eval/depth_evaluation.h"
#include "eval/evaluate.h"
#include "eval/workspace_evaluation.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

const std::filesystem::path kSmall =
    SourceDir() / "example_images" / "small";

TEST(Reconstruct, SmallSceneRegistersEveryPhotoWithAccurateCamerasAndResumes) {
  const TempDir workspace;
  SilentProgress progress;
  const ReconstructSummary summary =
      Reconstruct(kSmall / "images", workspace.Path(), {}, progress);
  EXPECT_EQ(summary.images_found, 12);
  EXPECT_EQ(summary.images_registered, 12);
  EXPECT_GT(summary.points3d, 300u);
  EXPECT_LT(summary.mean_reprojection_error_px, 1.0);
  EXPECT_TRUE(summary.plausibility.Plausible());
  // The workspace layout of docs/design.md: an undistorted PINHOLE model and its images.
  const SparseModel model = ReadSparseModel(workspace.Path() / "sparse");
  EXPECT_EQ(model.Cameras().front().model, CameraModel::kPinhole);
  EXPECT_TRUE(std::filesystem::exists(workspace.Path() / "images" / "0000.png"));
  EXPECT_TRUE(std::filesystem::exists(workspace.Path() / "report.json"));
  EXPECT_TRUE(std::filesystem::exists(workspace.Path() / "logs" / "mapper.log"));

  const PoseEvaluation evaluation =
      EvaluatePoses(model, ReadSparseModel(SceneFolder{kSmall}.Training().sparse));
  EXPECT_EQ(evaluation.registered, 12);
  EXPECT_LT(evaluation.rotation_error_mean_deg, 0.5);
  EXPECT_LT(evaluation.center_error_rel_mean, 0.02);
  EXPECT_EQ(evaluation.alignment.inliers, 12);
  // The mapper's model without its observations over 1 px from their points, adjusted again.
  const SparseModel raw = ReadSparseModel(Workspace(workspace.Path()).RawModel());
  double worst_px = 0;
  for (const Point3D& point : raw.Points3D()) {
    for (const TrackElement& element : point.track) {
      const SparseImage& image = raw.ImageById(element.image_id);
      const std::optional<Eigen::Vector2d> pixel =
          raw.CameraById(image.camera_id).Project(image.cam_from_world * point.xyz);
      ASSERT_TRUE(pixel.has_value());
      worst_px = std::max(worst_px, (*pixel - image.points2d[element.point2d_idx].xy).norm());
    }
  }
  // The adjustment after the filter moves a few a little past it.
  EXPECT_LT(worst_px, 1.5);
  const std::vector<std::string> notes = summary.notes;
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [](const std::string& note) {
    return note.find("observations over 1.00 px from their points dropped") != std::string::npos;
  })) << ::testing::PrintToString(notes);

  // Multi-view stereo: the dense files of docs/design.md, and depth measured in the true cameras.
  for (const char* file : {"stereo/depth_maps/0005.png.geometric.bin",
                           "stereo/depth_maps/0005.png.photometric.bin",
                           "stereo/normal_maps/0005.png.geometric.bin", "depth/0005.exr",
                           "depth/0005.confidence.exr"}) {
    EXPECT_TRUE(std::filesystem::exists(workspace.Path() / file)) << file;
  }
  const SceneFolder scene{kSmall};
  const DepthEvaluation depth = EvaluateDepth(
      model, Workspace(workspace.Path()).DepthDir(), ReadSparseModel(scene.Training().sparse),
      scene.Training().depth, evaluation.alignment.target_from_source, {});
  EXPECT_EQ(depth.views, 12);
  // Measured 0.61 and 0.69 with SfM cameras (their 0.3 degree error costs accuracy).
  EXPECT_GT(depth.within_2pct, 0.5);
  EXPECT_GT(depth.completeness, 0.6);
  // The bias follows the SfM cameras' scale through the alignment, which changes from run to
  // run (COLMAP's threads): -0.0012 to -0.0041 in six runs, 0.0055 once in a CI run. 1% still
  // catches a depth convention or unit error.
  EXPECT_LT(std::abs(depth.signed_median), 0.01);

  // A second identical run skips every stage.
  const ReconstructSummary again = Reconstruct(kSmall / "images", workspace.Path(), {}, progress);
  for (const StageRecord& stage : again.stages) EXPECT_TRUE(stage.skipped) << stage.name;
  EXPECT_EQ(again.images_registered, 12);

  // The held-out novel photos registered into the SfM model land where the ground truth has
  // them (through the alignment), and the training cameras stay where they were.
  const SparseModel novel = ReadSparseModel(scene.Novel().sparse);
  std::vector<std::string> names;
  for (const SparseImage& image : novel.Images()) names.push_back(image.name);
  const std::filesystem::path work = workspace.Path() / "evaluation" / "novel_registration";
  const HeldOutRegistration held_out =
      RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, work, progress);
  // Measured: 3 of the 4 register (one seen from 1 m up, across the scene, shares too few
  // features with the arc); evaluate takes that one's pose from the alignment.
  EXPECT_GE(held_out.registered.size(), 3u) << held_out.note;
  // Each pose comes with the camera it was solved with: the workspace's, unmoved.
  const Camera shared = ReadSparseModel(Workspace(workspace.Path()).RawModel()).Cameras().front();
  for (const auto& [name, posed] : held_out.registered) EXPECT_EQ(posed.camera.params, shared.params) << name;
  std::map<std::string, double> registered_angles_deg;
  for (const SparseImage& image : novel.Images()) {
    if (!held_out.registered.contains(image.name)) continue;
    const Rigid3d pose =
        evaluation.alignment.target_from_source.TransformPose(held_out.registered.at(image.name).cam_from_world);
    const double angle_deg =
        pose.rotation.angularDistance(image.cam_from_world.rotation) * 180 / std::numbers::pi;
    registered_angles_deg[image.name] = angle_deg;
    // As accurate as the training cameras, within a factor of 2.
    EXPECT_LT(angle_deg, 2 * evaluation.rotation_error_max_deg) << image.name;
    EXPECT_LT((CameraCenter(pose) - CameraCenter(image.cam_from_world)).norm(),
              2 * evaluation.center_error_rel_max * evaluation.extent)
        << image.name;
  }
  const SparseModel registered = ReadSparseModel(work / "model");
  for (const SparseImage& image : model.Images()) {
    const auto same = std::find_if(registered.Images().begin(), registered.Images().end(),
                                   [&](const SparseImage& r) { return r.name == image.name; });
    ASSERT_NE(same, registered.Images().end()) << image.name;
    EXPECT_LT((CameraCenter(same->cam_from_world) - CameraCenter(image.cam_from_world)).norm(), 1e-9)
        << image.name << " moved";
  }
  EXPECT_NE(RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, work, progress)
                .note.find("reused"),
            std::string::npos);
  // Registered again elsewhere, the photos come out at the same poses to the bit (their
  // features numbered by name, their matches verified in fixed parts).
  const HeldOutRegistration elsewhere =
      RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, workspace.Path() / "again", progress);
  ASSERT_EQ(elsewhere.registered.size(), held_out.registered.size()) << elsewhere.note;
  for (const auto& [name, posed] : held_out.registered) {
    const Rigid3d& again_pose = elsewhere.registered.at(name).cam_from_world;
    EXPECT_TRUE(again_pose.rotation.coeffs() == posed.cam_from_world.rotation.coeffs()) << name;
    EXPECT_TRUE(again_pose.translation == posed.cam_from_world.translation) << name;
  }
  const HeldOutRegistration clash = RegisterHeldOutPhotos(
      workspace.Path(), scene.Training().images, {"0003.png"}, workspace.Path() / "clash", progress);
  // A held-out photo may share a training photo's name (here it is that very photo): it is
  // registered all the same, onto the training camera.
  ASSERT_TRUE(clash.registered.contains("0003.png")) << clash.note;
  const Rigid3d& twin = clash.registered.at("0003.png").cam_from_world;
  const Rigid3d& original = model.FindImageByName("0003.png")->cam_from_world;
  EXPECT_LT(RotationAngleDeg(twin.rotation, original.rotation), 0.05);
  EXPECT_LT((CameraCenter(twin) - CameraCenter(original)).norm(), 0.002 * evaluation.extent);
  // A held-out photo colmap cannot read as it is (16-bit TIFF: FreeImage refuses it) is
  // converted for the registration.
  const TempDir tiff_dir;
  ASSERT_TRUE(OIIO::ImageBuf((scene.Training().images / "0003.png").string())
                  .write((tiff_dir.Path() / "0003.tif").string(), OIIO::TypeDesc::UINT16));
  const HeldOutRegistration tiff = RegisterHeldOutPhotos(workspace.Path(), tiff_dir.Path(), {"0003.tif"},
                                                         workspace.Path() / "tiff", progress);
  ASSERT_TRUE(tiff.registered.contains("0003.tif")) << tiff.note;
  EXPECT_LT(RotationAngleDeg(tiff.registered.at("0003.tif").cam_from_world.rotation, original.rotation), 0.05);

  // Real photos come with cameras and held-out photos but no depth: everything else is scored,
  // and what is not is said.
  const TempDir real_dir;
  for (const char* part : {"images", "gt/sparse", "novel/images", "novel/sparse"}) {
    std::filesystem::create_directories(real_dir.Path() / part);
    std::filesystem::copy(kSmall / part, real_dir.Path() / part, std::filesystem::copy_options::recursive);
  }
  const WorkspaceEvaluation real = EvaluateWorkspace(Workspace(workspace.Path()), SceneFolder{real_dir.Path()}, {},
                                                     progress);
  EXPECT_FALSE(real.depth.has_value());
  EXPECT_FALSE(real.fused.has_value());
  ASSERT_TRUE(real.mesh.has_value());
  EXPECT_FALSE(real.mesh->accuracy.has_value());
  EXPECT_GT(real.mesh->texture.psnr_mean, 20);
  ASSERT_EQ(real.not_scored.size(), 1u);
  EXPECT_NE(real.not_scored[0].find("no ground-truth depth"), std::string::npos) << real.not_scored[0];
  ASSERT_TRUE(real.novel.has_value());
  EXPECT_EQ(real.novel->result.views, 4);
  EXPECT_GT(real.novel->result.psnr_mean, 20);
  EXPECT_GE(real.novel->result.psnr_exposure_matched_mean, real.novel->result.psnr_mean - 0.5);
  // Each registered photo's pose error against the truth is reported, as measured above.
  ASSERT_EQ(real.novel->registered_pose_errors.size(), registered_angles_deg.size());
  for (const ImagePoseError& error : real.novel->registered_pose_errors) {
    ASSERT_TRUE(registered_angles_deg.contains(error.name)) << error.name;
    EXPECT_NEAR(error.rotation_error_deg, registered_angles_deg.at(error.name), 1e-6) << error.name;
    EXPECT_LT(error.center_error_rel, 2 * evaluation.center_error_rel_max) << error.name;
  }
}

TEST(Reconstruct, KnownCamerasAreKeptAndOnlyTriangulated) {
  const TempDir workspace;
  SilentProgress progress;
  ReconstructOptions options;
  options.known_cameras = SceneFolder{kSmall}.Training().sparse;
  const ReconstructSummary summary =
      Reconstruct(kSmall / "images", workspace.Path(), options, progress);
  EXPECT_EQ(summary.images_registered, 12);
  EXPECT_GT(summary.points3d, 300u);
  const SparseModel truth = ReadSparseModel(options.known_cameras);
  const SparseModel model = ReadSparseModel(workspace.Path() / "sparse");
  for (const SparseImage& image : truth.Images()) {
    const SparseImage* found = model.FindImageByName(image.name);
    ASSERT_NE(found, nullptr) << image.name;
    EXPECT_LT(RotationAngleDeg(found->cam_from_world.rotation, image.cam_from_world.rotation), 1e-9);
    EXPECT_LT((CameraCenter(found->cam_from_world) - CameraCenter(image.cam_from_world)).norm(), 1e-9);
  }
  EXPECT_DOUBLE_EQ(model.Cameras().front().FocalX(), truth.Cameras().front().FocalX());
  // PINHOLE cameras: nothing to undistort, the photos are copied (and COLMAP's stereo_fusion
  // below still accepts the workspace).
  const auto undistort = std::find_if(summary.stages.begin(), summary.stages.end(),
                                      [](const StageRecord& s) { return s.name == "undistort"; });
  ASSERT_NE(undistort, summary.stages.end());
  EXPECT_TRUE(undistort->skipped);
  EXPECT_NE(undistort->reason.find("no lens distortion"), std::string::npos) << undistort->reason;

  // The stereo alone, in the true cameras (measured: within 2% 0.82, completeness 0.88).
  const SceneFolder scene{kSmall};
  const DepthEvaluation depth =
      EvaluateDepth(model, Workspace(workspace.Path()).DepthDir(), truth, scene.Training().depth, {}, {});
  EXPECT_GT(depth.within_2pct, 0.6);
  EXPECT_GT(depth.completeness, 0.65);
  EXPECT_LT(depth.abs_rel_median, 0.002);
  EXPECT_LT(std::abs(depth.signed_median), 0.001);

  // Our fusion, and COLMAP's own stereo_fusion run on our dense workspace: COLMAP accepts it,
  // and both clouds lie on the true surfaces.
  const CloudAccuracy ours = MeasureCloud(ReadPly(Workspace(workspace.Path()).Fused()).vertices, truth,
                                          scene.Training().depth, {});
  EXPECT_GT(ours.points, 50000u);
  EXPECT_LT(ours.median_relative_distance, 0.005);
  EXPECT_GT(ours.within_1pct, 0.9);
  // Fused at half the photos' size, as the depth stage's cap has large photos fused: a
  // quarter of the points (each working pixel one), on the same surfaces.
  FusionOptions half_size;
  half_size.max_image_size = static_cast<int>(std::max(model.Cameras().front().width, model.Cameras().front().height) / 2);
  std::vector<Eigen::Vector3f> coarse_points;
  for (const FusedPoint& point : FuseWorkspace(Workspace(workspace.Path()), half_size, progress)) coarse_points.push_back(point.position);
  const CloudAccuracy coarse_accuracy = MeasureCloud(coarse_points, truth, scene.Training().depth, {});
  EXPECT_GT(coarse_accuracy.points, ours.points / 6);
  EXPECT_LT(coarse_accuracy.points, ours.points / 3);
  EXPECT_LT(coarse_accuracy.median_relative_distance, 0.005);
  EXPECT_GT(coarse_accuracy.within_1pct, 0.85);
  const std::filesystem::path colmap_ply = workspace.Path() / "colmap_fused.ply";
  Colmap().Run("stereo_fusion",
               {"--workspace_path", workspace.Path().string(), "--workspace_format", "COLMAP",
                "--input_type", "geometric", "--output_path", colmap_ply.string()},
               workspace.Path() / "logs" / "stereo_fusion.log", "stereo_fusion", 0, progress);
  const CloudAccuracy theirs =
      MeasureCloud(ReadPly(colmap_ply).vertices, truth, scene.Training().depth, {});
  EXPECT_GT(theirs.points, ours.points / 20);  // COLMAP keeps points seen by 5+ views; we 2+.
  EXPECT_LT(theirs.median_relative_distance, 0.005);
  EXPECT_GT(theirs.within_1pct, 0.9);

  // The textured mesh: on the true surfaces, readable by a standard tool, and its renders
  // reproduce the photos.
  const std::filesystem::path obj = Workspace(workspace.Path()).Mesh();
  const TriangleMesh mesh = ReadTexturedMesh(obj);
  EXPECT_GT(mesh.triangles.size(), 5000u);
  const CloudAccuracy vertices = MeasureCloud(mesh.vertices, truth, scene.Training().depth, {});
  EXPECT_LT(vertices.median_relative_distance, 0.005);
  EXPECT_GT(vertices.within_1pct, 0.8);
  std::vector<std::string> image_names;
  const std::vector<NamedCamera> cameras = CamerasOfModel(model, &image_names);
  const TexturedMeshScore texture = ScoreTexturedMesh(mesh, cameras, image_names, ReadWorkspaceColorGains(workspace.Path()),
                                                      workspace.Path() / "images", {});
  std::printf("[ measure ] textured mesh: PSNR %.2f dB, coverage %.4f\n", texture.psnr_mean, texture.coverage_mean);
  EXPECT_EQ(texture.views, 12);
  EXPECT_GE(texture.psnr_mean, 25);
  // Measured 0.490-0.50x from run to run since fusion merges surfaces fused again (a6fc65c): it
  // sat on the old 0.5 and failed two runs in three; 0.449 and 0.460 in two runs on 5 December
  // (Poisson's mesh differs from run to run), so the bound sits below that spread.
  EXPECT_GT(texture.coverage_mean, 0.42);
  const CliResult assimp = RunCommand("assimp info " + Quote(obj.string()));
  EXPECT_EQ(assimp.exit_code, 0) << assimp.output;
  EXPECT_NE(assimp.output.find("Faces:"), std::string::npos) << assimp.output;
  EXPECT_NE(assimp.output.find(std::to_string(mesh.triangles.size())), std::string::npos)
      << assimp.output;
  // The same mesh as binary glTF: valid for the Khronos validator, as many triangles.
  const std::filesystem::path glb = Workspace(workspace.Path()).MeshDir() / "mesh.glb";
  const CliResult validator = RunCommand(Quote((SourceDir() / "scripts" / "validate-glb").string()) + " " + Quote(glb.string()));
  EXPECT_EQ(validator.exit_code, 0) << validator.output;
  EXPECT_NE(validator.output.find("\"errors\":0,\"warnings\":0,"), std::string::npos) << validator.output;
  EXPECT_NE(validator.output.find("\"triangles\":" + std::to_string(mesh.triangles.size()) + ","), std::string::npos)
      << validator.output;
  // The mesh stage again on the same cloud, twice: the same files byte for byte (colmap's
  // Poisson runs on one thread, whose sums come in a fixed order).
  const MeshOptions mesh_options = MeshOptionsFor(Quality::kFast);
  MeshWorkspace(Workspace(workspace.Path()), Colmap(), mesh_options, progress);
  const std::string first = ReadFileBytes(obj);
  MeshWorkspace(Workspace(workspace.Path()), Colmap(), mesh_options, progress);
  EXPECT_TRUE(ReadFileBytes(obj) == first) << "the same cloud meshed twice gave two meshes";

  // The surface from the depth maps fused into a signed-distance volume instead (--mesher
  // tsdf): near the true surfaces, textured, the same files twice.
  MeshOptions tsdf_options = mesh_options;
  tsdf_options.mesher = Mesher::kTsdf;
  const MeshSummary tsdf = MeshWorkspace(Workspace(workspace.Path()), Colmap(), tsdf_options, progress);
  const TriangleMesh tsdf_mesh = ReadTexturedMesh(obj);
  const CloudAccuracy tsdf_vertices = MeasureCloud(tsdf_mesh.vertices, truth, scene.Training().depth, {});
  const TexturedMeshScore tsdf_texture = ScoreTexturedMesh(tsdf_mesh, cameras, image_names,
                                                           ReadWorkspaceColorGains(workspace.Path()),
                                                           workspace.Path() / "images", {});
  std::printf("[ measure ] tsdf mesh: %zu triangles (voxel %.4f, %zu blocks), vertices median %.4f%%, within 1%% "
              "%.3f; textured PSNR %.2f dB, coverage %.4f\n",
              tsdf_mesh.triangles.size(), tsdf.voxel_size, tsdf.voxel_blocks, 100 * tsdf_vertices.median_relative_distance,
              tsdf_vertices.within_1pct, tsdf_texture.psnr_mean, tsdf_texture.coverage_mean);
  // Measured: 86k triangles, vertices a median 0.17% off and 88% within 1% (Poisson's mesh
  // 0.5%-bounded above); textured 31.4 dB on 66% of the pixels against Poisson's 30.4 on 50%.
  EXPECT_EQ(tsdf.mesher, "tsdf");
  EXPECT_GT(tsdf_mesh.triangles.size(), 5000u);
  EXPECT_LT(tsdf_vertices.median_relative_distance, 0.005);
  EXPECT_GT(tsdf_vertices.within_1pct, 0.8);
  EXPECT_GE(tsdf_texture.psnr_mean, 28);
  EXPECT_GT(tsdf_texture.coverage_mean, 0.55);
  const std::string tsdf_first = ReadFileBytes(obj);
  MeshWorkspace(Workspace(workspace.Path()), Colmap(), tsdf_options, progress);
  EXPECT_TRUE(ReadFileBytes(obj) == tsdf_first) << "the same depth maps fused twice gave two meshes";

  // The OpenCV StereoSGBM baseline on the same workspace (it overwrites depth/): it works on
  // rectified pairs of these converging cameras, and PatchMatch beats it.
  const MvsSummary sgbm_run =
      RunSgbmStereo(Workspace(workspace.Path()), MvsOptionsFor(Quality::kBalanced).views, {}, progress);
  // Every view gets SGBM depth except, at times, the arc's end camera: whether one of its
  // selected sources lies to its right depends on the triangulated points (COLMAP runs
  // multi-threaded), and without one it is skipped, with that reason.
  EXPECT_EQ(sgbm_run.views.size() + sgbm_run.skipped.size(), 12u);
  EXPECT_GE(sgbm_run.views.size(), 11u);
  for (const std::string& skipped : sgbm_run.skipped) {
    EXPECT_NE(skipped.find("no source view to its right"), std::string::npos) << skipped;
  }
  const DepthEvaluation sgbm =
      EvaluateDepth(model, Workspace(workspace.Path()).DepthDir(), truth, scene.Training().depth, {}, {});
  EXPECT_GT(sgbm.completeness, 0.3);
  EXPECT_LT(sgbm.abs_rel_median, 0.01);
  EXPECT_LT(sgbm.within_2pct, depth.within_2pct);

  // Half resolution: the maps are written at half the photos' size (evaluate reads them at the
  // photos'), lose some accuracy, stay unbiased.
  MvsOptions half = MvsOptionsFor(Quality::kBalanced);
  half.image_scale = 0.5;
  RunMultiViewStereo(Workspace(workspace.Path()), half, "half scale", progress);
  const Camera& photo = truth.Cameras().front();
  const DepthMap half_depth = ReadDepthExr(Workspace(workspace.Path()).Depth("0000.png"));
  EXPECT_EQ(half_depth.Width(), std::lround(0.5 * static_cast<double>(photo.width)));
  EXPECT_EQ(half_depth.Height(), std::lround(0.5 * static_cast<double>(photo.height)));
  EXPECT_EQ(ReadColmapArray(Workspace(workspace.Path()).StereoNormalMap("0000.png", StereoPass::kGeometric)).width,
            half_depth.Width());
  // Fusion reads the half-size maps as if they were upsampled to the photos' size: the same cloud.
  FusionOptions half_fusion;
  half_fusion.image_scale = 0.5;
  const FusedPoints from_working_size = FuseWorkspace(Workspace(workspace.Path()), half_fusion, progress);
  const SparseModel sparse = ReadSparseModelWithoutKeypoints(Workspace(workspace.Path()).Sparse());
  std::vector<const SparseImage*> fused_views;
  for (const SparseImage& image : sparse.Images()) {
    if (std::filesystem::exists(Workspace(workspace.Path()).Depth(image.name))) fused_views.push_back(&image);
  }
  const ColorGains gains = ReadWorkspaceColorGains(workspace.Path());
  const LoadFusionView at_photo_size = [&](const SparseImage& image) {
    const Workspace ws(workspace.Path());
    const Camera& camera = sparse.CameraById(image.camera_id);
    const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
    const DenseArray normals = ReadColmapArray(ws.StereoNormalMap(image.name, StereoPass::kGeometric));
    const std::vector<size_t> nearest = PixelsAtCentres(normals.width, normals.height, width, height);
    const size_t map_pixels = static_cast<size_t>(normals.width) * static_cast<size_t>(normals.height);
    FusionViewMaps maps{ReadDepthExrAt(ws.Depth(image.name), width, height),
                        {width, height, 3, std::vector<float>(3 * nearest.size())}, ReadImage(ws.Image(image.name)),
                        gains.Of(image.name)};
    for (size_t c = 0; c < 3; ++c) {
      for (size_t i = 0; i < nearest.size(); ++i) {
        maps.normals.values[c * nearest.size() + i] = normals.values[c * map_pixels + nearest[i]];
      }
    }
    return maps;
  };
  const FusedPoints from_photo_size = FuseDepthMaps(sparse, fused_views, at_photo_size, half_fusion, progress);
  ASSERT_GT(from_working_size.size(), 5000u);
  ASSERT_EQ(from_working_size.size(), from_photo_size.size());
  for (size_t i = 0; i < from_working_size.size(); ++i) {
    ASSERT_EQ(from_working_size[i].position, from_photo_size[i].position) << i;
    ASSERT_EQ(from_working_size[i].color, from_photo_size[i].color) << i;
  }
  const DepthEvaluation coarse =
      EvaluateDepth(model, Workspace(workspace.Path()).DepthDir(), truth, scene.Training().depth, {}, {});
  std::printf("[ measure ] depth at half resolution: within 2%% %.3f (full %.3f), completeness %.3f\n",
              coarse.within_2pct, depth.within_2pct, coarse.completeness);
  EXPECT_GT(coarse.within_2pct, 0.5);  // 0.725 measured.
  EXPECT_LT(coarse.within_2pct, depth.within_2pct);
  EXPECT_GT(coarse.completeness, 0.6);
  EXPECT_LT(std::abs(coarse.signed_median), 0.002);
}

// The colmap feature_extractor command line `RegisterHeldOutPhotos` ran in `work`.
std::string HeldOutExtraction(const std::filesystem::path& work) {
  const std::string log = ReadFileBytes(work / "colmap.log");
  const size_t start = log.find("$ ");
  return start == std::string::npos ? log : log.substr(start, log.find('\n', start) - start);
}

// Held-out photos are extracted as the workspace's photos were (report.json records how):
// at --quality fast's scale and feature count, not balanced's.
TEST(Reconstruct, HeldOutPhotosAreExtractedAsTheWorkspacesPhotosWere) {
  const TempDir workspace;
  SilentProgress progress;
  ReconstructOptions options;
  options.quality = Quality::kFast;
  options.estimate_depth = false;
  Reconstruct(kSmall / "images", workspace.Path(), options, progress);
  const SceneFolder scene{kSmall};
  const SparseModel novel = ReadSparseModel(scene.Novel().sparse);
  std::vector<std::string> names;
  for (const SparseImage& image : novel.Images()) names.push_back(image.name);

  const HeldOutRegistration fast =
      RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, workspace.Path() / "fast", progress);
  EXPECT_GE(fast.registered.size(), 3u) << fast.note;  // 3 of 4, as with balanced's.
  const std::string fast_extraction = HeldOutExtraction(workspace.Path() / "fast");
  EXPECT_NE(fast_extraction.find("--SiftExtraction.max_image_size 1024 --SiftExtraction.max_num_features 2048"),
            std::string::npos) << fast_extraction;
  EXPECT_NE(fast.note.find("1024 px, 2048 features"), std::string::npos) << fast.note;

  // A report from before the settings were recorded: balanced's, as every workspace then had.
  const std::filesystem::path report_path = Workspace(workspace.Path()).Report();
  nlohmann::json report = nlohmann::json::parse(ReadFileBytes(report_path));
  ASSERT_EQ(report["reconstruct"]["features"]["max_num_features"], 2048) << report.dump();
  report["reconstruct"].erase("features");
  WriteFileAtomically(report_path, report.dump());
  RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, workspace.Path() / "older", progress);
  const std::string older_extraction = HeldOutExtraction(workspace.Path() / "older");
  EXPECT_NE(older_extraction.find("--SiftExtraction.max_image_size 2000 --SiftExtraction.max_num_features 4096"),
            std::string::npos) << older_extraction;

  // A damaged record is the workspace's fault, said as such, not a note that nothing registered.
  WriteFileAtomically(report_path, R"({"reconstruct": {"features": 7}})");
  EXPECT_THROW(
      RegisterHeldOutPhotos(workspace.Path(), scene.Novel().images, names, workspace.Path() / "damaged", progress),
      BadInputError);
}

TEST(Colmap, AFailingCommandNamesTheToolStatusAndLog) {
  const TempDir dir;
  SilentProgress progress;
  const Colmap colmap;
  try {
    colmap.Run("no_such_command", {}, dir.Path() / "logs" / "x.log", "x", 0, progress);
    FAIL() << "no error";
  } catch (const ToolError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("colmap no_such_command failed with exit status"), std::string::npos)
        << message;
    EXPECT_NE(message.find("x.log"), std::string::npos) << message;
  }
}

TEST(Colmap, ProgressLinesAreParsed) {
  EXPECT_EQ(ParseColmapProgress("Processed file [3/12]", 0).done, 3);
  EXPECT_EQ(ParseColmapProgress("Matching block [2/3, 1/3] in 1.2s", 0).done, 4);
  EXPECT_EQ(ParseColmapProgress("Matching block [2/3, 1/3] in 1.2s", 0).total, 9);
  EXPECT_EQ(ParseColmapProgress("Registering image #7 (5)", 12).done, 5);
  EXPECT_EQ(ParseColmapProgress("Registering image #7 (5)", 12).total, 12);
  EXPECT_EQ(ParseColmapProgress("Undistorting image [4/9]", 0).total, 9);
  EXPECT_EQ(ParseColmapProgress("Bundle adjustment report", 0).done, -1);
}

}  // namespace
}  // namespace parallax

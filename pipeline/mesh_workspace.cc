#include "pipeline/mesh_workspace.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/color_gains.h"
#include "core/error.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "geometry/obj.h"
#include "geometry/ply.h"
#include "geometry/simplify.h"
#include "mesh/support.h"
#include "mesh/tsdf_volume.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// The cameras, each photo read (and corrected by its color gain) only when the texture needs it.
std::vector<TextureView> LoadTextureViews(const Workspace& workspace, const SparseModel& model) {
  const ColorGains gains = ReadWorkspaceColorGains(workspace.Root());
  std::vector<TextureView> views;
  for (const SparseImage& image : model.Images()) {
    TextureView view;
    view.camera = model.CameraById(image.camera_id);
    view.cam_from_world = image.cam_from_world;
    view.load_color = [path = workspace.Image(image.name), gain = gains.Of(image.name)] {
      Image color = SrgbToLinear(ReadImage(path));
      ApplyGain(gain, color);
      return color;
    };
    views.push_back(std::move(view));
  }
  return views;
}

// The cameras of the photos with a depth map, each map read when needed. Photos held out of
// the depth stage have none.
std::vector<SupportView> LoadSupportViews(const Workspace& workspace, const SparseModel& model) {
  std::vector<SupportView> views;
  for (const SparseImage& image : model.Images()) {
    const fs::path depth = workspace.Depth(image.name);
    if (!fs::exists(depth)) continue;
    const Camera& camera = model.CameraById(image.camera_id);
    const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
    views.push_back(
        {camera, image.cam_from_world, [depth, width, height] { return ReadDepthExrAt(depth, width, height); }});
  }
  return views;
}

// The Poisson surface of <ws>/fused.ply, trimmed to where the cloud has data; the count of
// Poisson's own triangles in `poisson_triangles`. The cloud is only in memory in here.
TriangleMesh TrimmedPoissonSurface(const Workspace& workspace, const Colmap& colmap, const MeshOptions& options,
                                   Progress& progress, size_t& poisson_triangles) {
  const fs::path fused = workspace.Fused();
  const std::vector<Eigen::Vector3f> points = ReadPly(fused).vertices;
  if (points.size() < 100) {
    throw BadInputError(fused.string() + ": only " + std::to_string(points.size()) +
                        " fused points, too few to mesh");
  }
  const fs::path poisson = workspace.PoissonMesh();
  const fs::path temporary = workspace.PoissonMeshScratch();
  // One thread: Poisson's threads sum in no fixed order, and the same cloud would give
  // another mesh each run.
  colmap.Run("poisson_mesher",
             {"--input_path", fused.string(), "--output_path", temporary.string(),
              "--PoissonMeshing.depth", std::to_string(options.poisson_depth), "--PoissonMeshing.trim",
              std::to_string(options.poisson_trim), "--PoissonMeshing.num_threads", "1"},
             workspace.Log("mesh"), "mesh", 0, progress);
  fs::rename(temporary, poisson);

  progress.Update("trim", 0, 1);
  // colmap's solver now and then writes a NaN vertex: its triangles go, the rest is kept.
  const TriangleMesh raw = ReadPly(poisson, NonFiniteVertices::kDropTheirTriangles);
  poisson_triangles = raw.triangles.size();
  TriangleMesh trimmed = TrimToData(raw, points, options);
  progress.Update("trim", 1, 1);
  return trimmed;
}

// A photo's depth map and its camera scaled to the map's size (the depth stage's working size).
struct MapView {
  Camera camera;
  Rigid3d cam_from_world;
  DepthMap depth;
};

MapView ReadMapView(const Camera& photo_camera, const Rigid3d& cam_from_world, const fs::path& path) {
  MapView view{photo_camera, cam_from_world, ReadDepthExr(path)};
  const double sx = static_cast<double>(view.depth.Width()) / static_cast<double>(photo_camera.width);
  const double sy = static_cast<double>(view.depth.Height()) / static_cast<double>(photo_camera.height);
  view.camera = MakePinholeCamera(photo_camera.id, static_cast<uint64_t>(view.depth.Width()),
                                  static_cast<uint64_t>(view.depth.Height()), sx * photo_camera.FocalX(),
                                  sy * photo_camera.FocalY(), sx * photo_camera.PrincipalX(),
                                  sy * photo_camera.PrincipalY());
  return view;
}

// Scene units per map pixel at the map's median depth; nothing for a map without depth.
std::optional<double> MedianFootprint(const MapView& view) {
  std::vector<float> depths;
  for (const float d : view.depth.Values()) {
    if (d > 0) depths.push_back(d);
  }
  if (depths.empty()) return std::nullopt;
  const auto middle = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return static_cast<double>(*middle) / view.camera.FocalX();
}

// The depth maps of `model`'s photos fused into a signed-distance volume (mesh/tsdf_volume.h),
// each at its own size with its camera scaled to it, read one at a time; the voxel is
// options.tsdf_voxel_pixels of a map's pixels at the median over the maps of their median
// depth, so it follows the depth stage's resolution as Poisson's octree follows the cloud's
// extent. Cells whose voxels fewer than options.tsdf_min_weight maps wrote make no surface;
// pieces no two maps support go with the floaters after.
TriangleMesh TsdfSurface(const Workspace& workspace, const SparseModel& model, const MeshOptions& options,
                         Progress& progress, MeshSummary& summary) {
  std::vector<const SparseImage*> images;
  std::vector<double> footprints;
  for (const SparseImage& image : model.Images()) {
    const fs::path path = workspace.Depth(image.name);
    if (!fs::exists(path)) continue;
    const std::optional<double> footprint =
        MedianFootprint(ReadMapView(model.CameraById(image.camera_id), image.cam_from_world, path));
    if (!footprint) continue;
    images.push_back(&image);
    footprints.push_back(*footprint);
  }
  if (images.empty()) throw BadInputError(workspace.DepthDir().string() + ": no depth maps to fuse into a volume");
  const auto middle = footprints.begin() + static_cast<std::ptrdiff_t>(footprints.size() / 2);
  std::nth_element(footprints.begin(), middle, footprints.end());
  TsdfOptions tsdf;
  tsdf.voxel_size = options.tsdf_voxel_pixels * *middle;
  tsdf.truncation = options.tsdf_truncation_voxels * tsdf.voxel_size;
  TsdfVolume volume(tsdf);
  for (size_t i = 0; i < images.size(); ++i) {
    progress.Update("volume", i, images.size());
    const MapView view = ReadMapView(model.CameraById(images[i]->camera_id), images[i]->cam_from_world,
                                     workspace.Depth(images[i]->name));
    volume.Integrate(view.camera, view.cam_from_world, view.depth);
  }
  progress.Update("volume", images.size(), images.size());
  summary.mesher = "tsdf";
  summary.voxel_size = tsdf.voxel_size;
  summary.voxel_blocks = volume.Blocks();
  TriangleMesh surface = volume.Mesh(options.tsdf_min_weight);
  summary.poisson_triangles = surface.triangles.size();
  return surface;
}

}  // namespace

MeshSummary MeshWorkspace(const Workspace& workspace, const Colmap& colmap, const MeshOptions& options,
                          Progress& progress) {
  options.Check();
  MeshSummary summary;
  const SparseModel model = ReadSparseModelWithoutKeypoints(workspace.Sparse());
  const TriangleMesh trimmed =
      options.mesher == Mesher::kTsdf
          ? TsdfSurface(workspace, model, options, progress, summary)
          : TrimmedPoissonSurface(workspace, colmap, options, progress, summary.poisson_triangles);
  progress.Update("floaters", 0, 1);
  SupportSummary support;
  const TriangleMesh surface =
      DropUnsupportedPieces(trimmed, LoadSupportViews(workspace, model), options.support, support);
  summary.pieces = support.pieces;
  summary.dropped_pieces = support.dropped_pieces;
  summary.dropped_triangles = support.dropped_triangles;
  progress.Update("floaters", 1, 1);
  summary.triangles = surface.triangles.size();
  summary.vertices = surface.vertices.size();

  progress.Update("texture", 0, 1);
  const std::vector<TextureView> views = LoadTextureViews(workspace, model);
  {  // The full atlas is freed before the display copy's is made.
    TextureSummary texture;
    const TriangleMesh textured = TextureMesh(surface.vertices, surface.triangles, views, options.texture, texture);
    WriteTexturedMesh(workspace.MeshDir(), textured);
    summary.texels_per_edge = texture.texels_per_edge;
    summary.untextured_triangles = texture.untextured_triangles;
    summary.atlas_width = textured.atlas.Width();
    summary.atlas_height = textured.atlas.Height();
  }
  progress.Update("texture", 1, 1);

  const fs::path display = workspace.DisplayMeshDir();
  if (surface.triangles.size() > options.display_max_triangles) {
    progress.Update("display mesh", 0, 1);
    const TriangleMesh simplified = SimplifyMesh(surface, options.display_max_triangles);
    TextureSummary display_texture;
    WriteTexturedMesh(display, TextureMesh(simplified.vertices, simplified.triangles, views, options.texture,
                                           display_texture));
    summary.display_triangles = simplified.triangles.size();
    progress.Update("display mesh", 1, 1);
  } else {
    fs::remove_all(display);  // A stale one from a larger mesh would be shown instead.
  }
  return summary;
}

}  // namespace parallax

#include "mesh/poisson.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "core/error.h"
#include "core/hash.h"
#include "core/color_gains.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "core/check.h"
#include "geometry/ply.h"
#include "geometry/simplify.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Points hashed into cubic cells, for "is there a point within r of here" queries.
class PointGrid {
 public:
  PointGrid(const std::vector<Eigen::Vector3f>& points, float cell) : cell_(cell) {
    for (const Eigen::Vector3f& p : points) cells_[Key(Cell(p))].push_back(p);
  }

  bool AnyWithin(const Eigen::Vector3f& query, float radius) const {
    const Eigen::Vector3i centre = Cell(query);
    const float squared = radius * radius;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto found = cells_.find(Key(centre + Eigen::Vector3i(dx, dy, dz)));
          if (found == cells_.end()) continue;
          for (const Eigen::Vector3f& p : found->second) {
            if ((p - query).squaredNorm() <= squared) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3f& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    return MixBits((static_cast<uint64_t>(static_cast<uint32_t>(c.x())) << 42) ^
                   (static_cast<uint64_t>(static_cast<uint32_t>(c.y())) << 21) ^
                   static_cast<uint64_t>(static_cast<uint32_t>(c.z())));
  }

  float cell_;
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3f>> cells_;
};

// Poisson's octree cell size: the cloud's bounding cube over 2^depth.
float OctreeCell(const std::vector<Eigen::Vector3f>& points, int depth) {
  Eigen::Vector3f low = points.front(), high = points.front();
  for (const Eigen::Vector3f& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  return (high - low).maxCoeff() / static_cast<float>(1 << depth);
}

// Drops triangles with a corner far from the data, and the vertices no triangle uses.
TriangleMesh Trim(const TriangleMesh& mesh, const PointGrid& grid, float radius) {
  std::vector<uint8_t> near(mesh.vertices.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    near[v] = mesh.vertices[v].allFinite() && grid.AnyWithin(mesh.vertices[v], radius);
  }
  TriangleMesh trimmed;
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    if (!near[static_cast<size_t>(triangle[0])] || !near[static_cast<size_t>(triangle[1])] ||
        !near[static_cast<size_t>(triangle[2])]) {
      continue;
    }
    Eigen::Vector3i renumbered;
    for (int c = 0; c < 3; ++c) {
      int& index = new_index[static_cast<size_t>(triangle[c])];
      if (index < 0) {
        index = static_cast<int>(trimmed.vertices.size());
        trimmed.vertices.push_back(mesh.vertices[static_cast<size_t>(triangle[c])]);
      }
      renumbered[c] = index;
    }
    trimmed.triangles.push_back(renumbered);
  }
  return trimmed;
}

// The cameras, each photo read (and corrected by its color gain) only when the texture needs it.
std::vector<TextureView> LoadTextureViews(const fs::path& workspace) {
  const Workspace ws(workspace);
  const SparseModel model = ReadSparseModelWithoutKeypoints(ws.Sparse());
  const ColorGains gains = ReadWorkspaceColorGains(workspace);
  std::vector<TextureView> views;
  for (const SparseImage& image : model.Images()) {
    TextureView view;
    view.camera = model.CameraById(image.camera_id);
    view.cam_from_world = image.cam_from_world;
    view.load_color = [path = ws.Image(image.name), gain = gains.Of(image.name)] {
      Image color = SrgbToLinear(ReadImage(path));
      ApplyGain(gain, color);
      return color;
    };
    views.push_back(std::move(view));
  }
  return views;
}

// The Poisson surface of <ws>/fused.ply, trimmed to where the cloud has data; the count of
// Poisson's own triangles in `poisson_triangles`. The cloud is only in memory in here.
TriangleMesh TrimmedPoissonSurface(const Workspace& ws, const Colmap& colmap, const MeshOptions& options,
                                   Progress& progress, size_t& poisson_triangles) {
  const fs::path fused = ws.Fused();
  const std::vector<Eigen::Vector3f> points = ReadPly(fused).vertices;
  if (points.size() < 100) {
    throw BadInputError(fused.string() + ": only " + std::to_string(points.size()) +
                        " fused points, too few to mesh");
  }
  const fs::path poisson = ws.PoissonMesh();
  const fs::path temporary = ws.PoissonMeshScratch();
  colmap.Run("poisson_mesher",
             {"--input_path", fused.string(), "--output_path", temporary.string(),
              "--PoissonMeshing.depth", std::to_string(options.poisson_depth), "--PoissonMeshing.trim",
              std::to_string(options.poisson_trim)},
             ws.Log("mesh"), "mesh", 0, progress);
  fs::rename(temporary, poisson);

  progress.Update("trim", 0, 1);
  // colmap's solver now and then writes a NaN vertex: its triangles go, the rest is kept.
  const TriangleMesh raw = ReadPly(poisson, NonFiniteVertices::kDropTheirTriangles);
  poisson_triangles = raw.triangles.size();
  const float cell = OctreeCell(points, options.poisson_depth);
  const float radius = static_cast<float>(options.max_cells_from_data) * cell;
  TriangleMesh trimmed = Trim(raw, PointGrid(points, radius), radius);
  progress.Update("trim", 1, 1);
  return trimmed;
}

}  // namespace

void MeshOptions::Check() const {
  RequireOption(poisson_depth >= 5 && poisson_depth <= 14, "MeshOptions.poisson_depth", poisson_depth, "[5, 14]");
  RequireOption(max_cells_from_data > 0, "MeshOptions.max_cells_from_data", max_cells_from_data, "> 0");
  RequireOption(poisson_trim >= 0, "MeshOptions.poisson_trim", poisson_trim, ">= 0");
  RequireOption(display_max_triangles >= 1, "MeshOptions.display_max_triangles",
                static_cast<double>(display_max_triangles), ">= 1");
  texture.Check();
}

MeshOptions MeshOptionsFor(Quality quality) {
  MeshOptions options;
  options.poisson_depth = quality == Quality::kFast ? 9 : quality == Quality::kBest ? 11 : 10;
  return options;
}

MeshSummary MeshWorkspace(const fs::path& workspace, const Colmap& colmap,
                          const MeshOptions& options, Progress& progress) {
  options.Check();
  const Workspace ws(workspace);
  MeshSummary summary;
  const TriangleMesh trimmed = TrimmedPoissonSurface(ws, colmap, options, progress, summary.poisson_triangles);
  summary.triangles = trimmed.triangles.size();
  summary.vertices = trimmed.vertices.size();

  progress.Update("texture", 0, 1);
  const std::vector<TextureView> views = LoadTextureViews(workspace);
  {  // The full atlas is freed before the display copy's is made.
    TextureSummary texture;
    const TriangleMesh textured = TextureMesh(trimmed.vertices, trimmed.triangles, views, options.texture, texture);
    WriteTexturedMesh(ws.MeshDir(), textured);
    summary.texels_per_edge = texture.texels_per_edge;
    summary.untextured_triangles = texture.untextured_triangles;
    summary.atlas_width = textured.atlas.Width();
    summary.atlas_height = textured.atlas.Height();
  }
  progress.Update("texture", 1, 1);

  const fs::path display = ws.DisplayMeshDir();
  if (trimmed.triangles.size() > options.display_max_triangles) {
    progress.Update("display mesh", 0, 1);
    const TriangleMesh simplified = SimplifyMesh(trimmed, options.display_max_triangles);
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

void to_json(nlohmann::json& json, const MeshSummary& mesh) {
  json = {{"poisson_triangles", mesh.poisson_triangles},
          {"triangles", mesh.triangles},
          {"vertices", mesh.vertices},
          {"texels_per_edge", mesh.texels_per_edge},
          {"untextured_triangles", mesh.untextured_triangles},
          {"atlas_size", {mesh.atlas_width, mesh.atlas_height}},
          {"display_triangles", mesh.display_triangles}};
}

void from_json(const nlohmann::json& json, MeshSummary& mesh) {
  json.at("poisson_triangles").get_to(mesh.poisson_triangles);
  json.at("triangles").get_to(mesh.triangles);
  json.at("vertices").get_to(mesh.vertices);
  json.at("texels_per_edge").get_to(mesh.texels_per_edge);
  json.at("untextured_triangles").get_to(mesh.untextured_triangles);
  json.at("atlas_size").at(0).get_to(mesh.atlas_width);
  json.at("atlas_size").at(1).get_to(mesh.atlas_height);
  json.at("display_triangles").get_to(mesh.display_triangles);
}

}  // namespace parallax

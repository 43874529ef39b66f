#include "mesh/poisson.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "core/error.h"
#include "core/hash.h"
#include "core/check.h"
#include "geometry/mesh_pieces.h"

namespace parallax {
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
  std::vector<uint8_t> keep(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    keep[t] = near[static_cast<size_t>(triangle[0])] && near[static_cast<size_t>(triangle[1])] &&
              near[static_cast<size_t>(triangle[2])];
  }
  TriangleMesh trimmed = KeepTriangles(mesh, keep);
  trimmed.normals.clear();  // Only positions go on to the texture.
  trimmed.colors.clear();
  return trimmed;
}

}  // namespace

void MeshOptions::Check() const {
  RequireOption(poisson_depth >= 5 && poisson_depth <= 14, "MeshOptions.poisson_depth", poisson_depth, "[5, 14]");
  RequireOption(max_cells_from_data > 0, "MeshOptions.max_cells_from_data", max_cells_from_data, "> 0");
  RequireOption(poisson_trim >= 0, "MeshOptions.poisson_trim", poisson_trim, ">= 0");
  RequireOption(tsdf_voxel_pixels > 0, "MeshOptions.tsdf_voxel_pixels", tsdf_voxel_pixels, "> 0");
  RequireOption(tsdf_truncation_voxels >= 1, "MeshOptions.tsdf_truncation_voxels", tsdf_truncation_voxels, ">= 1");
  RequireOption(tsdf_min_weight > 0, "MeshOptions.tsdf_min_weight", tsdf_min_weight, "> 0");
  RequireOption(display_max_triangles >= 1, "MeshOptions.display_max_triangles",
                static_cast<double>(display_max_triangles), ">= 1");
  support.Check();
  texture.Check();
}

MeshOptions MeshOptionsFor(Quality quality) {
  MeshOptions options;
  options.poisson_depth = quality == Quality::kFast ? 9 : quality == Quality::kBest ? 11 : 10;
  return options;
}

TriangleMesh TrimToData(const TriangleMesh& surface, const std::vector<Eigen::Vector3f>& points,
                        const MeshOptions& options) {
  if (points.empty()) throw InternalError("TrimToData: no points to trim to");
  const float cell = OctreeCell(points, options.poisson_depth);
  const float radius = static_cast<float>(options.max_cells_from_data) * cell;
  return Trim(surface, PointGrid(points, radius), radius);
}

void to_json(nlohmann::json& json, const MeshSummary& mesh) {
  json = {{"poisson_triangles", mesh.poisson_triangles},
          {"triangles", mesh.triangles},
          {"vertices", mesh.vertices},
          {"texels_per_edge", mesh.texels_per_edge},
          {"untextured_triangles", mesh.untextured_triangles},
          {"atlas_size", {mesh.atlas_width, mesh.atlas_height}},
          {"display_triangles", mesh.display_triangles},
          {"pieces", mesh.pieces},
          {"dropped_pieces", mesh.dropped_pieces},
          {"dropped_triangles", mesh.dropped_triangles},
          {"mesher", mesh.mesher}};
  if (mesh.mesher == "tsdf") {
    json["voxel_size"] = mesh.voxel_size;
    json["voxel_blocks"] = mesh.voxel_blocks;
  }
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
  json.at("pieces").get_to(mesh.pieces);
  json.at("dropped_pieces").get_to(mesh.dropped_pieces);
  json.at("dropped_triangles").get_to(mesh.dropped_triangles);
  mesh.mesher = json.value("mesher", "poisson");  // Summaries from before the choice.
  mesh.voxel_size = json.value("voxel_size", 0.0);
  mesh.voxel_blocks = json.value("voxel_blocks", size_t{0});
}

}  // namespace parallax

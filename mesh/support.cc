#include "mesh/support.h"

#include <cmath>

#include "core/check.h"
#include "geometry/mesh_pieces.h"

namespace parallax {
namespace {

enum class VertexInView : uint8_t { kUnseen, kOnSurface, kInFront };

// Where each vertex lies against the view's depth map: on its surface, in the space in front
// of it, or unseen (outside the frame, no depth there, or behind the surface).
std::vector<VertexInView> ClassifyVertices(const std::vector<Eigen::Vector3f>& vertices, const SupportView& view,
                                           const DepthMap& depth, double tolerance) {
  std::vector<VertexInView> where(vertices.size(), VertexInView::kUnseen);
  if (depth.Empty()) return where;
  const double scale_x = depth.Width() / static_cast<double>(view.camera.width);
  const double scale_y = depth.Height() / static_cast<double>(view.camera.height);
  for (size_t v = 0; v < vertices.size(); ++v) {
    const Eigen::Vector3d in_cam = view.cam_from_world * vertices[v].cast<double>();
    const std::optional<Eigen::Vector2d> pixel = view.camera.Project(in_cam);
    if (!pixel) continue;
    const double x = std::floor(pixel->x() * scale_x), y = std::floor(pixel->y() * scale_y);
    if (!(x >= 0 && y >= 0 && x < depth.Width() && y < depth.Height())) continue;
    const double measured = depth.At(static_cast<int>(x), static_cast<int>(y));
    if (!(measured > 0)) continue;
    const double offset = in_cam.z() - measured;
    if (std::abs(offset) <= tolerance * measured) {
      where[v] = VertexInView::kOnSurface;
    } else if (offset < 0) {
      where[v] = VertexInView::kInFront;
    }
  }
  return where;
}

}  // namespace

void SupportOptions::Check() const {
  RequireOption(depth_tolerance > 0 && depth_tolerance < 1, "SupportOptions.depth_tolerance", depth_tolerance,
                "(0, 1)");
  RequireOption(min_views >= 1, "SupportOptions.min_views", min_views, ">= 1");
}

TriangleMesh DropUnsupportedPieces(const TriangleMesh& mesh, const std::vector<SupportView>& views,
                                   const SupportOptions& options, SupportSummary& summary) {
  options.Check();
  int piece_count = 0;
  const std::vector<int> piece = PieceOfEachVertex(mesh, piece_count);
  std::vector<int> supporting_views(static_cast<size_t>(piece_count), 0);
  std::vector<size_t> on_surface(static_cast<size_t>(piece_count)), in_front(static_cast<size_t>(piece_count));
  for (const SupportView& view : views) {
    const std::vector<VertexInView> where =
        ClassifyVertices(mesh.vertices, view, view.load_depth(), options.depth_tolerance);
    std::fill(on_surface.begin(), on_surface.end(), 0);
    std::fill(in_front.begin(), in_front.end(), 0);
    for (size_t v = 0; v < where.size(); ++v) {
      const auto p = static_cast<size_t>(piece[v]);
      on_surface[p] += where[v] == VertexInView::kOnSurface;
      in_front[p] += where[v] == VertexInView::kInFront;
    }
    for (size_t p = 0; p < supporting_views.size(); ++p) {
      supporting_views[p] += on_surface[p] > 0 && on_surface[p] >= in_front[p];
    }
  }
  std::vector<uint8_t> keep(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    keep[t] = supporting_views[static_cast<size_t>(piece[static_cast<size_t>(mesh.triangles[t][0])])] >=
              options.min_views;
  }
  std::vector<uint8_t> piece_has_triangles(static_cast<size_t>(piece_count), 0);
  for (const Eigen::Vector3i& triangle : mesh.triangles) {
    piece_has_triangles[static_cast<size_t>(piece[static_cast<size_t>(triangle[0])])] = 1;
  }
  summary = {};
  for (size_t p = 0; p < piece_has_triangles.size(); ++p) {
    if (!piece_has_triangles[p]) continue;
    ++summary.pieces;
    summary.dropped_pieces += supporting_views[p] < options.min_views;
  }
  for (const uint8_t kept : keep) summary.dropped_triangles += !kept;
  return KeepTriangles(mesh, keep);
}

}  // namespace parallax

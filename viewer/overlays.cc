#include "viewer/overlays.h"

#include <algorithm>
#include <cmath>

#include "viewer/shaders.h"
#include "viewer/view_math.h"

namespace parallax {
namespace {

using gpu::Vertex;

// A round grid step: 1, 2 or 5 times a power of ten, at least `minimum`.
double NiceStep(double minimum) {
  const double power = std::pow(10.0, std::floor(std::log10(minimum)));
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    if (factor * power >= minimum) return factor * power;
  }
  return 10 * power;
}

void AddLine(std::vector<Vertex>& lines, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
             const Eigen::Vector3f& color) {
  for (const Eigen::Vector3d& p : {a, b}) {
    lines.push_back({{static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())},
                     {0, 0, 0}, {0, 0}, {color.x(), color.y(), color.z()}});
  }
}

}  // namespace

std::vector<gpu::Vertex> PointVertices(const std::vector<ColoredPoint>& points) {
  std::vector<Vertex> vertices;
  vertices.reserve(points.size());
  for (const ColoredPoint& p : points) {
    vertices.push_back({{p.position.x(), p.position.y(), p.position.z()},
                        {p.normal.x(), p.normal.y(), p.normal.z()},
                        {0, 0},
                        {p.color[0] / 255.0f, p.color[1] / 255.0f, p.color[2] / 255.0f}});
  }
  return vertices;
}

std::vector<gpu::Vertex> FrustumLines(const std::vector<ViewerSource>& sources, double depth) {
  std::vector<Vertex> lines;
  const Eigen::Vector3f color(0.9f, 0.45f, 0.1f);
  for (const ViewerSource& source : sources) {
    const Rigid3d world_from_cam = source.cam_from_world.Inverse();
    const Eigen::Vector3d centre = CameraCenter(source.cam_from_world);
    const double w = static_cast<double>(source.camera.width), h = static_cast<double>(source.camera.height);
    Eigen::Vector3d corners[4];
    const double pixels[4][2] = {{0, 0}, {w, 0}, {w, h}, {0, h}};
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d ray((pixels[i][0] - source.camera.PrincipalX()) / source.camera.FocalX(),
                                (pixels[i][1] - source.camera.PrincipalY()) / source.camera.FocalY(), 1);
      corners[i] = world_from_cam * (depth * ray);
    }
    for (int i = 0; i < 4; ++i) {
      AddLine(lines, centre, corners[i], color);
      AddLine(lines, corners[i], corners[(i + 1) % 4], color);
    }
    const Eigen::Vector3d top = 0.5 * (corners[0] + corners[1]);
    AddLine(lines, top, top + 0.3 * (top - 0.5 * (corners[2] + corners[3])), color);
  }
  return lines;
}

double FrustumDepth(const ViewerScene& scene) {
  const double size = static_cast<double>(scene.extent.diagonal().norm());
  double depth = 0.04 * size;
  const size_t n = scene.sources.size();
  if (n < 2 || n > 2000) return depth;  // Quadratic below; 2000 cameras take a few ms.
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const double d = (CameraCenter(scene.sources[i].cam_from_world) - CameraCenter(scene.sources[j].cam_from_world)).norm();
      nearest[i] = std::min(nearest[i], d);
      nearest[j] = std::min(nearest[j], d);
    }
  }
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(n / 2), nearest.end());
  return std::clamp(nearest[n / 2], 0.005 * size, depth);
}


std::vector<gpu::Vertex> GridLines(const ViewerScene& scene) {
  const Eigen::Vector3d up = scene.up;
  const Eigen::Vector3d centre = scene.Centre().cast<double>();
  double height = 0;  // Of the grid plane along `up`, relative to the extent's centre.
  if (scene.ground) {
    height = -scene.ground->SignedDistance(centre);
  } else {
    height = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner =
          scene.extent.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).cast<double>();
      height = std::min(height, up.dot(corner - centre));
    }
  }
  const Eigen::Vector3d reference = std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = (reference - up * up.dot(reference)).normalized();
  const Eigen::Vector3d v = up.cross(u);
  double half = 1e-6 * std::max(1.0, static_cast<double>(scene.Radius()));
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d offset = scene.extent.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c)).cast<double>() - centre;
    half = std::max({half, std::abs(u.dot(offset)), std::abs(v.dot(offset))});
  }
  constexpr int kMinCells = 16;  // Across the footprint.
  const double step = NiceStep(2 * half / kMinCells);
  const int cells = static_cast<int>(std::ceil(half / step - 1e-9));
  // Just under the ground, so the ground mesh hides the grid instead of z-fighting with it;
  // centred on a multiple of the step, so lines fall on round coordinates.
  Eigen::Vector3d origin = centre + (height - 1e-3 * static_cast<double>(scene.Radius())) * up;
  origin += (std::round(u.dot(origin) / step) * step - u.dot(origin)) * u +
            (std::round(v.dot(origin) / step) * step - v.dot(origin)) * v;
  const double extent = (cells + 1) * step;
  std::vector<Vertex> lines;
  const Eigen::Vector3f color(0.55f, 0.55f, 0.55f);
  for (int i = -cells - 1; i <= cells + 1; ++i) {
    const double s = i * step;
    AddLine(lines, origin + s * u - extent * v, origin + s * u + extent * v, color);
    AddLine(lines, origin - extent * u + s * v, origin + extent * u + s * v, color);
  }
  return lines;
}

OverlayPass::OverlayPass(const ViewerScene& scene)
    : program_("lines", shaders::kLineVertex, shaders::kLineFragment), frustum_depth_(FrustumDepth(scene)) {
  for (const ViewerSource& source : scene.sources) source_centres_.push_back(CameraCenter(source.cam_from_world));
  if (!scene.sources.empty()) frusta_ = gpu::Upload(FrustumLines(scene.sources, frustum_depth_));
  grid_ = gpu::Upload(GridLines(scene));
}

void OverlayPass::Draw(const FrameContext& frame) const {
  program_.Use();
  program_.Set("u_clip_from_world", frame.clip_from_world);
  program_.Set("u_linear_output", frame.hdr ? 1 : 0);
  if (frame.settings.show_grid) {
    glBindVertexArray(grid_.vao.Get());
    glDrawArrays(GL_LINES, 0, grid_.count);
  }
  if (frame.settings.show_cameras && frusta_.count > 0) DrawFrusta(CameraCenter(frame.view.cam_from_world));
  glBindVertexArray(0);
}

void OverlayPass::DrawFrusta(const Eigen::Vector3d& eye_centre) const {
  glBindVertexArray(frusta_.vao.Get());
  GLint first = 0;
  for (size_t i = 0; i < source_centres_.size(); ++i) {
    if ((source_centres_[i] - eye_centre).norm() >= 3 * frustum_depth_) continue;
    const GLint skipped = static_cast<GLint>(i) * kFrustumVertices;
    if (skipped > first) glDrawArrays(GL_LINES, first, skipped - first);
    first = skipped + kFrustumVertices;
  }
  if (frusta_.count > first) glDrawArrays(GL_LINES, first, frusta_.count - first);
}

}  // namespace parallax

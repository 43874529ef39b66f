#include "core/camera.h"

#include <array>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace parallax {
namespace {

struct ModelInfo {
  CameraModel model;
  std::string_view name;
  int num_params;
  bool single_focal;  // f, cx, cy, ... instead of fx, fy, cx, cy, ...
};

constexpr std::array<ModelInfo, 11> kModels = {{
    {CameraModel::kSimplePinhole, "SIMPLE_PINHOLE", 3, true},
    {CameraModel::kPinhole, "PINHOLE", 4, false},
    {CameraModel::kSimpleRadial, "SIMPLE_RADIAL", 4, true},
    {CameraModel::kRadial, "RADIAL", 5, true},
    {CameraModel::kOpenCV, "OPENCV", 8, false},
    {CameraModel::kOpenCVFisheye, "OPENCV_FISHEYE", 8, false},
    {CameraModel::kFullOpenCV, "FULL_OPENCV", 12, false},
    {CameraModel::kFOV, "FOV", 5, false},
    {CameraModel::kSimpleRadialFisheye, "SIMPLE_RADIAL_FISHEYE", 4, true},
    {CameraModel::kRadialFisheye, "RADIAL_FISHEYE", 5, true},
    {CameraModel::kThinPrismFisheye, "THIN_PRISM_FISHEYE", 12, false},
}};

const ModelInfo& Info(CameraModel model) {
  const int id = static_cast<int>(model);
  if (id < 0 || id >= static_cast<int>(kModels.size())) {
    throw InternalError("unknown camera model id " + std::to_string(id));
  }
  return kModels[static_cast<size_t>(id)];
}

int FirstPrincipalIndex(CameraModel model) { return Info(model).single_focal ? 1 : 2; }

// Radial coefficients (k1, k2) of the supported models; zero where the model has none.
Eigen::Vector2d RadialCoefficients(const Camera& camera) {
  const auto& p = camera.params;
  switch (camera.model) {
    case CameraModel::kSimpleRadial: return {p[3], 0.0};
    case CameraModel::kRadial: return {p[3], p[4]};
    case CameraModel::kOpenCV: return {p[4], p[5]};
    default: return {0.0, 0.0};
  }
}

void RequireProjection(const Camera& camera) {
  if (!IsProjectionSupported(camera.model)) {
    throw InternalError("camera model " + std::string(CameraModelName(camera.model)) +
                        " is read and written, but not projected by parallax");
  }
}

// Newton's method tolerances for Undistort: distorted coordinates are normalised (~1), so an
// absolute tolerance far below a pixel at any focal length up to 1e6 px is used.
constexpr int kMaxNewtonIterations = 100;
constexpr double kNewtonTolerance = 1e-14;

}  // namespace

std::string_view CameraModelName(CameraModel model) { return Info(model).name; }

std::optional<CameraModel> CameraModelNamed(std::string_view name) {
  for (const ModelInfo& info : kModels) {
    if (info.name == name) return info.model;
  }
  return std::nullopt;
}

std::optional<CameraModel> CameraModelWithId(int id) {
  if (id < 0 || id >= static_cast<int>(kModels.size())) return std::nullopt;
  return kModels[static_cast<size_t>(id)].model;
}

int NumCameraParams(CameraModel model) { return Info(model).num_params; }

bool IsProjectionSupported(CameraModel model) {
  return static_cast<int>(model) >= 0 && static_cast<int>(model) <= 4;
}

std::string Camera::Problem() const {
  const std::string where = "camera " + std::to_string(id) + " (" + std::string(CameraModelName(model)) + ")";
  if (static_cast<int>(params.size()) != NumCameraParams(model)) {
    return where + ": expected " + std::to_string(NumCameraParams(model)) + " parameters, got " +
           std::to_string(params.size());
  }
  if (width == 0 || height == 0) {
    return where + ": image size " + std::to_string(width) + "x" + std::to_string(height) + " is empty";
  }
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) return where + ": parameter " + std::to_string(i) + " is not finite";
  }
  if (!(FocalX() > 0 && FocalY() > 0)) return where + ": focal length must be positive";
  return "";
}

void Camera::Check() const {
  if (std::string problem = Problem(); !problem.empty()) throw InternalError(problem);
}

double Camera::FocalX() const { return params.at(0); }
double Camera::FocalY() const { return Info(model).single_focal ? params.at(0) : params.at(1); }
double Camera::PrincipalX() const { return params.at(FirstPrincipalIndex(model)); }
double Camera::PrincipalY() const { return params.at(FirstPrincipalIndex(model) + 1); }

bool Camera::HasDistortion() const {
  const int first_extra = FirstPrincipalIndex(model) + 2;
  for (size_t i = static_cast<size_t>(first_extra); i < params.size(); ++i) {
    if (params[i] != 0) return true;
  }
  return false;
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& normalized) const {
  RequireProjection(*this);
  const double u = normalized.x();
  const double v = normalized.y();
  const double r2 = u * u + v * v;
  const Eigen::Vector2d k = RadialCoefficients(*this);
  const double radial = k[0] * r2 + k[1] * r2 * r2;
  Eigen::Vector2d delta(u * radial, v * radial);
  if (model == CameraModel::kOpenCV) {
    const double p1 = params[6];
    const double p2 = params[7];
    delta.x() += 2 * p1 * u * v + p2 * (r2 + 2 * u * u);
    delta.y() += 2 * p2 * u * v + p1 * (r2 + 2 * v * v);
  }
  return normalized + delta;
}

double Camera::MaxInvertibleRadius() const {
  // d/dr [r (1 + k1 r^2 + k2 r^4)] = 1 + 3 k1 s + 5 k2 s^2 with s = r^2: the first positive
  // root bounds the monotonic (invertible) part. Tangential terms are small and ignored here;
  // Undistort still checks its Jacobian.
  const Eigen::Vector2d k = RadialCoefficients(*this);
  const double a = 5 * k[1], b = 3 * k[0], c = 1;
  double s = std::numeric_limits<double>::infinity();
  if (a == 0) {
    if (b < 0) s = -c / b;
  } else {
    const double discriminant = b * b - 4 * a * c;
    if (discriminant >= 0) {
      // Numerically stable roots (no cancellation between -b and the square root).
      const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
      for (const double root : {q / a, q != 0 ? c / q : -1.0}) {
        if (root > 0) s = std::min(s, root);
      }
    }
  }
  return std::sqrt(s);
}

std::optional<Eigen::Vector2d> Camera::Undistort(const Eigen::Vector2d& distorted) const {
  RequireProjection(*this);
  if (!distorted.allFinite()) return std::nullopt;
  if (!HasDistortion()) return distorted;
  const double max_radius = MaxInvertibleRadius();
  Eigen::Vector2d x = distorted;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const Eigen::Vector2d residual = Distort(x) - distorted;
    if (residual.norm() <= kNewtonTolerance * (1 + distorted.norm())) {
      if (x.norm() > max_radius) return std::nullopt;  // Converged on the folded-back branch.
      return x;
    }
    // Central differences: the step is relative to x so it stays meaningful at any scale.
    Eigen::Matrix2d jacobian;
    for (int axis = 0; axis < 2; ++axis) {
      const double step = 1e-7 * std::max(1.0, std::abs(x[axis]));
      Eigen::Vector2d plus = x, minus = x;
      plus[axis] += step;
      minus[axis] -= step;
      jacobian.col(axis) = (Distort(plus) - Distort(minus)) / (2 * step);
    }
    const double determinant = jacobian.determinant();
    if (!(determinant > 1e-12)) return std::nullopt;  // Distortion folds over here.
    x -= jacobian.inverse() * residual;
    if (!x.allFinite()) return std::nullopt;
  }
  return std::nullopt;
}

std::optional<Eigen::Vector2d> Camera::Project(const Eigen::Vector3d& point_in_cam) const {
  RequireProjection(*this);
  const double z = point_in_cam.z();
  if (!(z > 0) || !point_in_cam.allFinite()) return std::nullopt;
  const Eigen::Vector2d normalized = point_in_cam.head<2>() / z;
  if (!normalized.allFinite()) return std::nullopt;
  if (HasDistortion() && normalized.norm() > MaxInvertibleRadius()) return std::nullopt;
  const Eigen::Vector2d distorted = HasDistortion() ? Distort(normalized) : normalized;
  const Eigen::Vector2d pixel(FocalX() * distorted.x() + PrincipalX(),
                              FocalY() * distorted.y() + PrincipalY());
  if (!pixel.allFinite()) return std::nullopt;
  return pixel;
}

std::optional<Eigen::Vector3d> Camera::Unproject(const Eigen::Vector2d& pixel) const {
  RequireProjection(*this);
  const Eigen::Vector2d distorted((pixel.x() - PrincipalX()) / FocalX(),
                                  (pixel.y() - PrincipalY()) / FocalY());
  const std::optional<Eigen::Vector2d> normalized = Undistort(distorted);
  if (!normalized) return std::nullopt;
  return Eigen::Vector3d(normalized->x(), normalized->y(), 1.0);
}

std::optional<Eigen::Vector3d> Camera::Unproject(const Eigen::Vector2d& pixel,
                                                 double depth) const {
  if (!(depth > 0) || !std::isfinite(depth)) return std::nullopt;
  const std::optional<Eigen::Vector3d> ray = Unproject(pixel);
  if (!ray) return std::nullopt;
  return *ray * depth;
}

Camera MakePinholeCamera(uint32_t id, uint64_t width, uint64_t height, double fx, double fy,
                         double cx, double cy) {
  Camera camera;
  camera.id = id;
  camera.model = CameraModel::kPinhole;
  camera.width = width;
  camera.height = height;
  camera.params = {fx, fy, cx, cy};
  camera.Check();
  return camera;
}

}  // namespace parallax

#pragma once
// Camera models exactly as COLMAP defines them: the same names, ids and parameter order.
//
// Common principles:
//  - Image coordinates are continuous pixels; pixel centres lie at integer + 0.5 (COLMAP).
//  - The camera frame is x right, y down, z forward.
//  - Distortion acts on normalised coordinates (x/z, y/z), as in COLMAP.
//  - Functions that can fail for geometric reasons (a point behind the camera, a pixel beyond
//    the range where the distortion can be inverted) return std::nullopt: never garbage.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace parallax {

// Values are COLMAP's model ids, as stored in cameras.bin.
enum class CameraModel : int {
  kSimplePinhole = 0,       // f, cx, cy
  kPinhole = 1,             // fx, fy, cx, cy
  kSimpleRadial = 2,        // f, cx, cy, k
  kRadial = 3,              // f, cx, cy, k1, k2
  kOpenCV = 4,              // fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCVFisheye = 5,       // read and written only
  kFullOpenCV = 6,          // read and written only
  kFOV = 7,                 // read and written only
  kSimpleRadialFisheye = 8, // read and written only
  kRadialFisheye = 9,       // read and written only
  kThinPrismFisheye = 10,   // read and written only
};

// COLMAP's name ("SIMPLE_RADIAL"); throws InternalError for a value outside the enum.
std::string_view CameraModelName(CameraModel model);
// Inverse of CameraModelName: std::nullopt for a name COLMAP does not have.
std::optional<CameraModel> CameraModelNamed(std::string_view name);
// The model with COLMAP's id, or std::nullopt for an id outside COLMAP's models.
std::optional<CameraModel> CameraModelWithId(int id);
// Number of parameters COLMAP stores for the model.
int NumCameraParams(CameraModel model);
// Whether project/unproject are implemented for the model (the five models above).
bool IsProjectionSupported(CameraModel model);

struct Camera {
  uint32_t id = 0;
  CameraModel model = CameraModel::kPinhole;
  uint64_t width = 0;   // Pixels.
  uint64_t height = 0;  // Pixels.
  std::vector<double> params;  // COLMAP's order for `model`.

  // What makes the camera unusable (the parameter count does not fit the model, the size is
  // zero, a parameter is not finite, a focal length is not positive), or "" when it is usable.
  std::string Problem() const;
  // Throws InternalError with the Problem() unless it is "".
  void Check() const;

  double FocalX() const;
  double FocalY() const;
  double PrincipalX() const;
  double PrincipalY() const;
  bool HasDistortion() const;

  // Normalised undistorted coordinates -> normalised distorted coordinates.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalized) const;
  // Inverse of Distort by Newton's method. std::nullopt if it does not converge or if the
  // distortion is not invertible there (beyond the radius where r * (1 + k r^2 ...) turns back).
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& distorted) const;

  // Camera-frame point -> pixel. std::nullopt for points at or behind the camera plane, or
  // whose pixel would not be finite.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_cam) const;
  // Pixel -> normalised ray direction (x, y, 1) in the camera frame; std::nullopt where the
  // distortion cannot be inverted.
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& pixel) const;
  // Pixel + z-depth -> camera-frame point.
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& pixel, double depth) const;

  // Largest normalised radius up to which the radial distortion is monotonic (invertible);
  // +infinity when it is monotonic everywhere.
  double MaxInvertibleRadius() const;
};

// A PINHOLE camera (fx, fy, cx, cy); throws like Camera::Check.
Camera MakePinholeCamera(uint32_t id, uint64_t width, uint64_t height, double fx, double fy,
                         double cx, double cy);

}  // namespace parallax

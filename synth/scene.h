#pragma once
// The synthetic scene description that `parallax synth` renders: geometry, procedural
// materials, lights, sky and camera rigs. The JSON format is documented in
// docs/scene-format.md; world coordinates are z-up.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/pose.h"

namespace parallax {

enum class TextureType {
  kFbm,      // Multi-scale 3D value noise between two colors.
  kChecker,  // 3D checker of two colors, modulated by fine noise.
};

struct TextureDesc {
  TextureType type = TextureType::kFbm;
  Eigen::Vector3f color_a{0.2f, 0.2f, 0.2f};  // Linear RGB.
  Eigen::Vector3f color_b{0.8f, 0.8f, 0.8f};  // Linear RGB.
  float scale = 1;       // Largest feature size (fbm) or cell size (checker), scene units.
  int octaves = 6;       // Noise octaves, each half the size of the previous.
  float contrast = 1.5f; // > 1 pushes noise towards the two colors.
  uint32_t seed = 0;
};

struct MaterialDesc {
  TextureDesc texture;
  float specular = 0;      // Blinn-Phong specular weight (white highlight).
  float shininess = 32;    // Blinn-Phong exponent.
};

enum class ShapeType { kPlane, kBox, kSphere, kCylinder };

struct ObjectDesc {
  ShapeType type = ShapeType::kPlane;
  std::string material;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // Cylinder: centre of the base.
  Eigen::Vector3d size = Eigen::Vector3d::Ones();    // Plane: (x, y, -); box: (x, y, z).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(); // Plane only.
  double radius = 1;                                 // Sphere, cylinder.
  double height = 1;                                 // Cylinder.
  double yaw_deg = 0;                                // Box: rotation about +z.
};

enum class LightType { kDirectional, kPoint };

struct LightDesc {
  LightType type = LightType::kDirectional;
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  // Directional: travel direction.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     // Point.
  Eigen::Vector3f color{1, 1, 1};
  float intensity = 1;  // Irradiance (directional) or intensity (point, falls off as 1/d^2).
};

struct SkyDesc {
  Eigen::Vector3f zenith{0.25f, 0.45f, 0.85f};   // Linear RGB straight up.
  Eigen::Vector3f horizon{0.75f, 0.8f, 0.9f};    // Linear RGB at and below the horizon.
};

struct ImageDesc {
  int width = 320;
  int height = 240;
  double focal_px = 300;
  int supersampling = 2;  // s x s samples per pixel for color; depth at the pixel centre.
};

struct ViewDesc {
  std::string name;  // Image file name, e.g. "0003.png".
  Rigid3d cam_from_world;
};

struct SceneDesc {
  ImageDesc image;
  SkyDesc sky;
  float ambient = 0.2f;
  bool write_normals = false;
  std::map<std::string, MaterialDesc> materials;
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  std::vector<ViewDesc> training;
  std::vector<ViewDesc> novel;
};

// Parses and validates a scene. Throws BadInputError naming the file and the JSON location
// (line/column for syntax errors, the field path such as objects[2].radius otherwise).
SceneDesc ParseSceneJson(const std::string& json_text, const std::string& source_name);
SceneDesc ReadSceneJson(const std::filesystem::path& path);

}  // namespace parallax

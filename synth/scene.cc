#include "synth/scene.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {
namespace {

using Json = nlohmann::json;

// A JSON object being read, with its location for error messages ("objects[2]").
class Node {
 public:
  Node(const Json& json, std::string path, const std::string& source)
      : json_(json), path_(std::move(path)), source_(source) {
    if (!json_.is_object()) Fail("expected an object");
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw BadInputError(source_ + ": " + (path_.empty() ? "top level" : path_) + ": " + what);
  }

  // Rejects keys outside `allowed`, so a typo is an error rather than a silent default.
  void AllowOnly(const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : json_.items()) {
      if (!allowed.count(key)) Fail("unknown field '" + key + "'");
    }
  }

  bool Has(const std::string& key) const { return json_.contains(key); }
  std::string Key(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

  Node Child(const std::string& key) const {
    if (!Has(key)) Fail("missing field '" + key + "'");
    return Node(json_.at(key), Key(key), source_);
  }

  const Json& Array(const std::string& key) const {
    if (!Has(key) || !json_.at(key).is_array()) Fail("field '" + key + "' must be an array");
    return json_.at(key);
  }

  double Number(const std::string& key, double fallback, double min, double max) const {
    if (!Has(key)) return fallback;
    return CheckedNumber(json_.at(key), Key(key), min, max);
  }
  double RequiredNumber(const std::string& key, double min, double max) const {
    if (!Has(key)) Fail("missing field '" + key + "'");
    return Number(key, 0, min, max);
  }

  std::string String(const std::string& key, const std::string& fallback) const {
    if (!Has(key)) return fallback;
    if (!json_.at(key).is_string()) Fail("field '" + key + "' must be a string");
    return json_.at(key).get<std::string>();
  }

  // An array of exactly `count` numbers.
  Eigen::VectorXd Numbers(const std::string& key, int count) const {
    const Json& value = json_.at(key);
    if (!value.is_array() || static_cast<int>(value.size()) != count) {
      Fail("field '" + key + "' must be an array of " + std::to_string(count) + " numbers");
    }
    Eigen::VectorXd vector(count);
    for (int i = 0; i < count; ++i) vector[i] = CheckedNumber(value[i], Key(key), -1e9, 1e9);
    return vector;
  }
  Eigen::Vector3d Vec3(const std::string& key, const Eigen::Vector3d& fallback) const {
    return Has(key) ? Eigen::Vector3d(Numbers(key, 3)) : fallback;
  }
  Eigen::Vector3d RequiredVec3(const std::string& key) const {
    if (!Has(key)) Fail("missing field '" + key + "'");
    return Vec3(key, Eigen::Vector3d::Zero());
  }
  Eigen::Vector3f Color(const std::string& key, const Eigen::Vector3f& fallback) const {
    const Eigen::Vector3d color = Vec3(key, fallback.cast<double>());
    if ((color.array() < 0).any()) Fail("field '" + key + "' must be a non-negative color");
    return color.cast<float>();
  }

  const std::string& Path() const { return path_; }
  const std::string& Source() const { return source_; }

 private:
  double CheckedNumber(const Json& value, const std::string& where, double min,
                       double max) const {
    if (!value.is_number()) throw BadInputError(source_ + ": " + where + ": expected a number");
    const double number = value.get<double>();
    if (!(number >= min && number <= max)) {
      char range[96];
      std::snprintf(range, sizeof(range), "expected a number in [%g, %g], got %g", min, max,
                    number);
      throw BadInputError(source_ + ": " + where + ": " + range);
    }
    return number;
  }

  const Json& json_;
  std::string path_;
  const std::string& source_;
};

template <typename Enum>
Enum ParseEnum(const Node& node, const std::string& key, const std::string& fallback,
               const std::vector<std::pair<std::string, Enum>>& names) {
  const std::string name = node.String(key, fallback);
  std::string expected;
  for (const auto& [candidate, value] : names) {
    if (candidate == name) return value;
    expected += (expected.empty() ? "" : ", ") + candidate;
  }
  node.Fail(key + " '" + name + "' is not one of: " + expected);
}

TextureDesc ParseTexture(const Node& node) {
  node.AllowOnly({"type", "colors", "scale", "octaves", "contrast", "seed"});
  TextureDesc texture;
  texture.type = ParseEnum<TextureType>(node, "type", "fbm",
                                        {{"fbm", TextureType::kFbm},
                                         {"checker", TextureType::kChecker}});
  if (node.Has("colors")) {
    const Json& colors = node.Array("colors");
    if (colors.size() != 2) node.Fail("colors must hold two colors");
    const Json pair = Json{{"a", colors[0]}, {"b", colors[1]}};
    const Node pair_node(pair, node.Key("colors"), node.Source());
    texture.color_a = pair_node.Color("a", Eigen::Vector3f::Zero());
    texture.color_b = pair_node.Color("b", Eigen::Vector3f::Zero());
  }
  texture.scale = static_cast<float>(node.Number("scale", texture.scale, 1e-6, 1e6));
  texture.octaves = static_cast<int>(node.Number("octaves", texture.octaves, 1, 16));
  texture.contrast = static_cast<float>(node.Number("contrast", texture.contrast, 0.1, 10));
  texture.seed = static_cast<uint32_t>(node.Number("seed", texture.seed, 0, 4294967295.0));
  return texture;
}

MaterialDesc ParseMaterial(const Node& node) {
  node.AllowOnly({"texture", "specular", "shininess"});
  MaterialDesc material;
  if (node.Has("texture")) material.texture = ParseTexture(node.Child("texture"));
  material.specular = static_cast<float>(node.Number("specular", material.specular, 0, 10));
  material.shininess = static_cast<float>(node.Number("shininess", material.shininess, 1, 1e4));
  return material;
}

ObjectDesc ParseObject(const Node& node, const std::map<std::string, MaterialDesc>& materials) {
  node.AllowOnly({"type", "material", "center", "size", "normal", "radius", "height", "yaw_deg"});
  ObjectDesc object;
  object.type = ParseEnum<ShapeType>(node, "type", "",
                                     {{"plane", ShapeType::kPlane},
                                      {"box", ShapeType::kBox},
                                      {"sphere", ShapeType::kSphere},
                                      {"cylinder", ShapeType::kCylinder}});
  object.material = node.String("material", "");
  if (!materials.count(object.material)) {
    node.Fail("material '" + object.material + "' is not defined in materials");
  }
  object.center = node.RequiredVec3("center");
  if (object.type == ShapeType::kPlane) {
    if (node.Has("size")) object.size << node.Numbers("size", 2), 1;
  } else {
    object.size = node.Vec3("size", object.size);
  }
  if ((object.size.array() <= 0).any()) node.Fail("size must be positive");
  object.normal = node.Vec3("normal", object.normal);
  if (!(object.normal.norm() > 0)) node.Fail("normal must not be zero");
  object.normal.normalize();
  object.radius = node.Number("radius", object.radius, 1e-6, 1e6);
  object.height = node.Number("height", object.height, 1e-6, 1e6);
  object.yaw_deg = node.Number("yaw_deg", 0, -360, 360);
  return object;
}

LightDesc ParseLight(const Node& node) {
  node.AllowOnly({"type", "direction", "position", "color", "intensity"});
  LightDesc light;
  light.type = ParseEnum<LightType>(node, "type", "directional",
                                    {{"directional", LightType::kDirectional},
                                     {"point", LightType::kPoint}});
  if (light.type == LightType::kDirectional) {
    light.direction = node.RequiredVec3("direction");
    if (!(light.direction.norm() > 0)) node.Fail("direction must not be zero");
    light.direction.normalize();
  } else {
    light.position = node.RequiredVec3("position");
  }
  light.color = node.Color("color", light.color);
  light.intensity = static_cast<float>(node.Number("intensity", light.intensity, 0, 1e9));
  return light;
}

std::string ViewName(const std::string& prefix, size_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%s%04zu.png", prefix.c_str(), index);
  return name;
}

// Appends the cameras of one rig entry: a full ring (or a helix of several turns), an arc, or
// explicit poses.
void ParseRig(const Node& node, const std::string& prefix, std::vector<ViewDesc>& views) {
  node.AllowOnly({"rig", "count", "radius", "height", "end_height", "turns", "center", "look_at",
                  "start_deg", "end_deg", "poses"});
  const std::string rig = node.String("rig", "");
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  auto add = [&](const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
    if (std::string problem = LookAtProblem(eye, target, up); !problem.empty()) node.Fail(problem);
    views.push_back({ViewName(prefix, views.size()), LookAt(eye, target, up)});
  };
  if (rig == "poses") {
    const Json& poses = node.Array("poses");
    for (size_t i = 0; i < poses.size(); ++i) {
      const Node pose(poses[i], node.Key("poses[" + std::to_string(i) + "]"), node.Source());
      pose.AllowOnly({"eye", "look_at"});
      add(pose.RequiredVec3("eye"), pose.RequiredVec3("look_at"));
    }
    return;
  }
  if (rig != "ring" && rig != "arc") node.Fail("rig '" + rig + "' is not one of: ring, arc, poses");
  const int count = static_cast<int>(node.RequiredNumber("count", 1, 10000));
  const double radius = node.RequiredNumber("radius", 1e-6, 1e9);
  const double height = node.Number("height", 0, -1e9, 1e9);
  const Eigen::Vector3d center = node.Vec3("center", Eigen::Vector3d::Zero());
  const Eigen::Vector3d look_at = node.Vec3("look_at", center);
  const double start_deg = node.Number("start_deg", 0, -3600, 3600);
  // A ring spaces `count` cameras evenly over `turns` turns, rising linearly from `height`
  // towards `end_height`, which the camera after the last would reach (so every k-th camera of
  // a ring is the ring of count / k); an arc puts its ends on start and end.
  if (rig == "arc" && (node.Has("turns") || node.Has("end_height"))) {
    node.Fail("'turns' and 'end_height' belong to a ring, not an arc");
  }
  const double turns = node.Number("turns", 1, 0.01, 100);
  const double end_height = node.Number("end_height", height, -1e9, 1e9);
  const double end_deg = node.Number("end_deg", start_deg + 360, -3600, 3600);
  const double step_deg = rig == "ring" ? 360.0 * turns / count
                                        : (count > 1 ? (end_deg - start_deg) / (count - 1) : 0);
  for (int i = 0; i < count; ++i) {
    const double angle = (start_deg + i * step_deg) * std::numbers::pi / 180;
    const double eye_height = height + (end_height - height) * i / count;
    const Eigen::Vector3d eye =
        center + Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), eye_height);
    add(eye, look_at);
  }
}

std::vector<ViewDesc> ParseViews(const Node& cameras, const std::string& key,
                                 const std::string& prefix) {
  std::vector<ViewDesc> views;
  if (!cameras.Has(key)) return views;
  const Json& rigs = cameras.Array(key);
  for (size_t i = 0; i < rigs.size(); ++i) {
    ParseRig(Node(rigs[i], cameras.Key(key + "[" + std::to_string(i) + "]"), cameras.Source()),
             prefix, views);
  }
  return views;
}

}  // namespace

SceneDesc ParseSceneJson(const std::string& json_text, const std::string& source_name) {
  Json json;
  try {
    json = Json::parse(json_text);
  } catch (const Json::exception& error) {
    // A syntax error (nlohmann's message carries "line L, column C" and what was expected),
    // or a number too large to represent (found by fuzzing: "7777...e777" overflows).
    std::string message = error.what();
    const size_t start = message.find("] ");
    throw BadInputError(source_name + ": " +
                        (start == std::string::npos ? message : message.substr(start + 2)));
  }
  const Node root(json, "", source_name);
  root.AllowOnly({"image", "sky", "ambient", "write_normals", "materials", "objects", "lights",
                  "cameras", "comment"});
  SceneDesc scene;
  if (root.Has("image")) {
    const Node image = root.Child("image");
    image.AllowOnly({"width", "height", "focal_px", "supersampling"});
    scene.image.width = static_cast<int>(image.Number("width", scene.image.width, 1, 16384));
    scene.image.height = static_cast<int>(image.Number("height", scene.image.height, 1, 16384));
    scene.image.focal_px = image.Number("focal_px", scene.image.focal_px, 1e-3, 1e7);
    scene.image.supersampling =
        static_cast<int>(image.Number("supersampling", scene.image.supersampling, 1, 8));
  }
  if (root.Has("sky")) {
    const Node sky = root.Child("sky");
    sky.AllowOnly({"zenith", "horizon"});
    scene.sky.zenith = sky.Color("zenith", scene.sky.zenith);
    scene.sky.horizon = sky.Color("horizon", scene.sky.horizon);
  }
  scene.ambient = static_cast<float>(root.Number("ambient", scene.ambient, 0, 100));
  if (root.Has("write_normals")) {
    if (!json.at("write_normals").is_boolean()) root.Fail("write_normals must be true or false");
    scene.write_normals = json.at("write_normals").get<bool>();
  }
  const Node materials = root.Child("materials");
  for (const auto& [name, value] : json.at("materials").items()) {
    scene.materials[name] = ParseMaterial(Node(value, materials.Key(name), source_name));
  }
  const Json& objects = root.Array("objects");
  for (size_t i = 0; i < objects.size(); ++i) {
    scene.objects.push_back(ParseObject(
        Node(objects[i], "objects[" + std::to_string(i) + "]", source_name), scene.materials));
  }
  if (scene.objects.empty()) root.Fail("objects is empty: nothing to render");
  if (root.Has("lights")) {
    const Json& lights = root.Array("lights");
    for (size_t i = 0; i < lights.size(); ++i) {
      scene.lights.push_back(
          ParseLight(Node(lights[i], "lights[" + std::to_string(i) + "]", source_name)));
    }
  }
  const Node cameras = root.Child("cameras");
  cameras.AllowOnly({"training", "novel"});
  scene.training = ParseViews(cameras, "training", "");
  scene.novel = ParseViews(cameras, "novel", "novel_");
  if (scene.training.empty()) cameras.Fail("training holds no camera");
  return scene;
}

SceneDesc ReadSceneJson(const std::filesystem::path& path) {
  return ParseSceneJson(ReadFileBytes(path), path.string());
}

}  // namespace parallax

#include "synth/scene.h"

#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

const char* kMinimal = R"({
  "materials": {"m": {}},
  "objects": [{"type": "sphere", "material": "m", "center": [0, 0, 1], "radius": 0.5}],
  "cameras": {"training": [{"rig": "ring", "count": 4, "radius": 3, "height": 1}]}
})";

std::string ErrorOf(const std::string& json) {
  try {
    ParseSceneJson(json, "scene.json");
  } catch (const BadInputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(SceneJson, MinimalSceneGetsDocumentedDefaults) {
  const SceneDesc scene = ParseSceneJson(kMinimal, "scene.json");
  EXPECT_EQ(scene.image.width, 320);
  EXPECT_EQ(scene.training.size(), 4u);
  EXPECT_EQ(scene.training[3].name, "0003.png");
  EXPECT_TRUE(scene.novel.empty());
  // Ring cameras sit at the given radius and height, looking at the ring centre.
  EXPECT_NEAR(CameraCenter(scene.training[1].cam_from_world).head<2>().norm(), 3, 1e-12);
  EXPECT_NEAR(CameraCenter(scene.training[1].cam_from_world).z(), 1, 1e-12);
}

// kMinimal with `rig` as its training cameras.
std::string SceneWithRig(const std::string& rig) {
  return R"({"materials": {"m": {}},
             "objects": [{"type": "sphere", "material": "m", "center": [0, 0, 1], "radius": 0.5}],
             "cameras": {"training": [)" + rig + "]}}";
}

SceneDesc HelixScene(int count) {
  return ParseSceneJson(SceneWithRig(R"({"rig": "ring", "count": )" + std::to_string(count) +
                                     R"(, "radius": 3, "height": 1, "end_height": 3, "turns": 2,
                                        "start_deg": 10})"),
                        "scene.json");
}

TEST(SceneJson, EveryKthCameraOfAHelixIsTheHelixOfFewerCameras) {
  const SceneDesc dense = HelixScene(40);
  const SceneDesc sparse = HelixScene(10);
  ASSERT_EQ(sparse.training.size(), 10u);
  for (size_t i = 0; i < sparse.training.size(); ++i) {
    const Eigen::Vector3d expected = CameraCenter(dense.training[4 * i].cam_from_world);
    EXPECT_LT((CameraCenter(sparse.training[i].cam_from_world) - expected).norm(), 1e-9) << i;
  }
  // Two turns rising from 1 towards 3: camera 20 of 40 is back at the start angle, at 2.
  const Eigen::Vector3d start = CameraCenter(dense.training[0].cam_from_world);
  const Eigen::Vector3d half = CameraCenter(dense.training[20].cam_from_world);
  EXPECT_NEAR(start.z(), 1, 1e-12);
  EXPECT_NEAR(half.z(), 2, 1e-12);
  EXPECT_LT((half.head<2>() - start.head<2>()).norm(), 1e-9);
  EXPECT_NEAR(std::atan2(start.y(), start.x()) * 180 / std::numbers::pi, 10, 1e-9);
  EXPECT_NE(ErrorOf(SceneWithRig(R"({"rig": "arc", "count": 2, "radius": 1, "turns": 2})"))
                .find("belong to a ring"),
            std::string::npos);
}

TEST(SceneJson, SyntaxErrorsNameTheFileLineAndColumn) {
  const std::string message = ErrorOf("{\n  \"materials\": {,\n}");
  EXPECT_NE(message.find("scene.json"), std::string::npos) << message;
  EXPECT_NE(message.find("line 2"), std::string::npos) << message;
  EXPECT_NE(message.find("column"), std::string::npos) << message;
}

TEST(SceneJson, FieldErrorsNameTheFieldPath) {
  std::string json = kMinimal;
  json.replace(json.find("\"radius\": 0.5"), 13, "\"radius\": -2");
  EXPECT_NE(ErrorOf(json).find("objects[0].radius"), std::string::npos) << ErrorOf(json);

  json = kMinimal;
  json.replace(json.find("\"radius\": 0.5"), 13, "\"radus\": 0.5");
  EXPECT_NE(ErrorOf(json).find("unknown field 'radus'"), std::string::npos) << ErrorOf(json);

  json = kMinimal;
  json.replace(json.find("\"material\": \"m\""), 15, "\"material\": \"x\"");
  EXPECT_NE(ErrorOf(json).find("material 'x' is not defined"), std::string::npos);

  json = kMinimal;
  json.replace(json.find("\"sphere\""), 8, "\"torus\"");
  EXPECT_NE(ErrorOf(json).find("type 'torus' is not one of"), std::string::npos);

  json = kMinimal;
  json.replace(json.find("\"count\": 4"), 10, "\"count\": \"four\"");
  EXPECT_NE(ErrorOf(json).find("cameras.training[0].count: expected a number"),
            std::string::npos)
      << ErrorOf(json);
}

TEST(SceneJson, CameraLookingStraightDownTheUpAxisIsAnError) {
  const std::string json = R"({
    "materials": {"m": {}},
    "objects": [{"type": "plane", "material": "m", "center": [0, 0, 0]}],
    "cameras": {"training": [{"rig": "poses", "poses": [{"eye": [0, 0, 5], "look_at": [0, 0, 0]}]}]}
  })";
  EXPECT_NE(ErrorOf(json).find("cameras.training[0]"), std::string::npos) << ErrorOf(json);
}

}  // namespace
}  // namespace parallax

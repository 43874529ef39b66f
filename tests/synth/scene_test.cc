#include "synth/scene.h"

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

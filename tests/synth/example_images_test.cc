// The committed example scenes are exactly what `parallax synth` makes of their scene.json.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "synth/synth.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

void ExpectSynthReproduces(const std::string& scene_name) {
  const fs::path committed = fs::path(PARALLAX_SOURCE_DIR) / "example_images" / scene_name;
  const TempDir out;
  const std::string json = ReadFileBytes(committed / "scene.json");
  SilentProgress progress;
  RenderSceneFolder(ParseSceneJson(json, "scene.json"), json, out.Path(), {}, progress);
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out.Path())) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), out.Path());
    ASSERT_TRUE(fs::exists(committed / relative)) << relative << " is not committed";
    EXPECT_TRUE(ReadFileBytes(entry.path()) == ReadFileBytes(committed / relative))
        << relative << " differs from the committed file";
    ++compared;
  }
  size_t committed_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(committed)) {
    committed_files += entry.is_regular_file();
  }
  EXPECT_EQ(static_cast<size_t>(compared), committed_files) << "stray committed files";
}

TEST(ExampleImages, SynthReproducesTheCommittedSmallSceneByteForByte) {
  ExpectSynthReproduces("small");
}

TEST(ExampleImages, SynthReproducesTheCommittedCourtyardByteForByte) {
  ExpectSynthReproduces("courtyard");
}

}  // namespace
}  // namespace parallax

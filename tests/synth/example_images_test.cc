// The committed example scenes are what `parallax synth` makes of their scene.json: byte for
// byte on the machine that made them, up to the last bit of a few samples on another CPU.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/image.h"
#include "synth/synth.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

// Embree picks its ray-triangle kernels by CPU (SSE, AVX2, AVX-512), which may round a hit
// distance differently in its last bit: an image made on another machine may differ from the
// committed one by about one step of its storage at some samples (1/255 in a PNG, a half's
// last bit in the normals, a few float ulps in the depth), and by more only where a ray grazes
// an edge and hits on one machine, misses on the other: at 1 sample in 2,000 at most.
double StorageStep(const fs::path& relative, double value) {
  if (relative.extension() == ".png") return 1.0 / 255;
  const bool half = relative.parent_path().filename() == "normal";
  return std::ldexp(std::max(1.0, std::abs(value)), half ? -10 : -20);
}

void ExpectSameUpToTheLastBit(const fs::path& made, const fs::path& committed, const fs::path& relative) {
  const Image a = ReadImage(made), b = ReadImage(committed);
  ASSERT_EQ(a.Width(), b.Width()) << relative;
  ASSERT_EQ(a.Height(), b.Height()) << relative;
  ASSERT_EQ(a.Pixels().size(), b.Pixels().size()) << relative;
  size_t differing = 0, beyond_a_step = 0;
  for (size_t i = 0; i < a.Pixels().size(); ++i) {
    const double x = a.Pixels()[i], y = b.Pixels()[i];
    differing += x != y;
    beyond_a_step += std::abs(x - y) > 1.01 * StorageStep(relative, y);
  }
  EXPECT_LE(beyond_a_step, a.Pixels().size() / 2000) << relative << ": " << beyond_a_step
                                                      << " samples differ by more than a step";
  if (relative.extension() == ".png") {
    EXPECT_LE(differing, a.Pixels().size() / 100) << relative << ": " << differing << " samples differ";
  }
}

void ExpectSynthReproduces(const std::string& scene_name) {
  const fs::path committed = SourceDir() / "example_images" / scene_name;
  const TempDir out;
  const std::string json = ReadFileBytes(committed / "scene.json");
  SilentProgress progress;
  RenderSceneFolder(ParseSceneJson(json, "scene.json"), json, out.Path(), {}, progress);
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out.Path())) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), out.Path());
    ASSERT_TRUE(fs::exists(committed / relative)) << relative << " is not committed";
    ++compared;
    if (ReadFileBytes(entry.path()) == ReadFileBytes(committed / relative)) continue;
    const std::string extension = relative.extension().string();
    EXPECT_TRUE(extension == ".png" || extension == ".exr") << relative << " differs from the committed file";
    if (extension == ".png" || extension == ".exr") ExpectSameUpToTheLastBit(entry.path(), committed / relative, relative);
  }
  size_t committed_files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(committed)) {
    committed_files += entry.is_regular_file();
  }
  EXPECT_EQ(static_cast<size_t>(compared), committed_files) << "stray committed files";
}

TEST(ExampleImages, SynthReproducesTheCommittedSmallScene) {
  ExpectSynthReproduces("small");
}

TEST(ExampleImages, SynthReproducesTheCommittedCourtyard) {
  ExpectSynthReproduces("courtyard");
}

}  // namespace
}  // namespace parallax

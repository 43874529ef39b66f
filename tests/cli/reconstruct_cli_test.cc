// Every error path of `parallax reconstruct`, through the real executable: exit code and
// message. Input is validated before colmap starts, so most run in well under a second each;
// those that need colmap's verdict on the photos run it on a few small ones.
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/sparse_model.h"
#include "tests/cli_runner.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmallImages = SourceDir() / "example_images" / "small" / "images";
const fs::path kCourtyardImages = SourceDir() / "example_images" / "courtyard" / "images";
// 16 of the courtyard's 24 photos, 15 degrees apart on its ring: the arc of 225 degrees from
// 0016 through 0023 to 0007, matched in 120 pairs instead of 276. On this side of the ring
// photos two apart share at least 47 verified matches (fast quality); across the other side
// 0006 and 0008 share none, and an arc there split the model on half the runs (0000 to 0015,
// and 0000 to 0019, with photos of two sizes). The counts the tests expect follow from 16.
constexpr int kArcPhotos = 16;
std::string ArcStem(int i) {
  char stem[8];
  std::snprintf(stem, sizeof stem, "%04d", (16 + i) % 24);
  return stem;
}

void ExpectFailure(const CliResult& result, int exit_code, const std::string& expected) {
  EXPECT_EQ(result.exit_code, exit_code) << result.output;
  EXPECT_NE(result.output.find(expected), std::string::npos)
      << "expected '" << expected << "' in:\n" << result.output;
}

std::string Reconstruct(const fs::path& photos, const fs::path& workspace,
                        const std::string& flags = "") {
  return "reconstruct " + Quote(photos.string()) + " " + Quote(workspace.string()) + " " + flags;
}

TEST(ReconstructCli, ColmapMissingExitsThreeAndSaysHowToInstall) {
  const TempDir dir;
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--colmap /no/colmap")),
                3, "apt-get install colmap");
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws"), "PATH=/nonexistent"),
                3, "colmap not found");
}

TEST(ReconstructCli, MissingOrEmptyFolderExitsTwo) {
  const TempDir dir;
  ExpectFailure(RunParallax(Reconstruct(dir.Path() / "missing", dir.Path() / "ws")), 2,
                "does not exist");
  fs::create_directories(dir.Path() / "empty");
  ExpectFailure(RunParallax(Reconstruct(dir.Path() / "empty", dir.Path() / "ws")), 2, "is empty");
}

TEST(ReconstructCli, FewerThanTwoReadableImagesExitsTwoListingTheRest) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos with spaces";
  fs::create_directories(photos);
  fs::copy_file(kSmallImages / "0000.png", photos / "0000.png");
  std::ofstream(photos / "notes.jpg") << "this is text";
  std::ofstream(photos / "zero.png");
  ExpectFailure(RunParallax(Reconstruct(photos, dir.Path() / "ws")), 2, "1 readable image");
  const CliResult result = RunParallax(Reconstruct(photos, dir.Path() / "ws"));
  EXPECT_NE(result.output.find("notes.jpg is not an image"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("zero.png is empty"), std::string::npos) << result.output;
}

TEST(ReconstructCli, UnreadableFilesAreSkippedWithAWarningWhenEnoughImagesRemain) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  for (const char* name : {"0000.png", "0001.png", "0002.png"}) {
    fs::copy_file(kSmallImages / name, photos / name);
  }
  std::ofstream(photos / "readme.txt") << "not a photo";
  const std::string png = [] {
    std::ifstream file(kSmallImages / "0003.png", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(file), {});
  }();
  std::ofstream(photos / "truncated.png", std::ios::binary).write(png.data(), 2000);
  const CliResult result = RunParallax(Reconstruct(photos, dir.Path() / "ws", "--dry-run"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("plan: 3 photos"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("skipped readme.txt"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("skipped truncated.png: it is corrupt or truncated"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("features     will run"), std::string::npos) << result.output;
}

// A JPEG whose header claims width x height (the frame marker's fields), its data that of a
// 64x64 photo: what a decompression bomb looks like before it is decoded.
void WriteJpegClaiming(const fs::path& path, int width, int height) {
  WriteImage(path, ReadImage(kSmallImages / "0000.png"), PixelFormat::kUint8);
  std::string bytes = [&] {
    std::ifstream file(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(file), {});
  }();
  for (size_t i = 0; i + 9 < bytes.size(); ++i) {
    const auto marker = static_cast<unsigned char>(bytes[i + 1]);
    if (static_cast<unsigned char>(bytes[i]) == 0xFF && (marker == 0xC0 || marker == 0xC2)) {
      bytes[i + 5] = static_cast<char>(height >> 8), bytes[i + 6] = static_cast<char>(height & 0xFF);
      bytes[i + 7] = static_cast<char>(width >> 8), bytes[i + 8] = static_cast<char>(width & 0xFF);
      break;
    }
  }
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(ReconstructCli, AnImageOverThePixelLimitIsSkippedFromItsHeader) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  for (const char* name : {"0000.png", "0001.png", "0002.png"}) fs::copy_file(kSmallImages / name, photos / name);
  WriteJpegClaiming(photos / "bomb.jpg", 60000, 60000);
  const CliResult result = RunParallax(Reconstruct(photos, dir.Path() / "ws", "--dry-run"));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("plan: 3 photos"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("skipped bomb.jpg: it is 60000x60000 (3600 MP), over the 128 MP limit"),
            std::string::npos)
      << result.output;
}

TEST(ReconstructCli, IdenticalCopiesAreSkippedAndCopiesAloneExitTwo) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  for (const char* name : {"0000.png", "0001.png", "0002.png"}) fs::copy_file(kSmallImages / name, photos / name);
  fs::copy_file(kSmallImages / "0001.png", photos / "0001 copy.png");
  const CliResult some = RunParallax(Reconstruct(photos, dir.Path() / "ws", "--dry-run"));
  EXPECT_EQ(some.exit_code, 0) << some.output;
  EXPECT_NE(some.output.find("plan: 3 photos"), std::string::npos) << some.output;
  EXPECT_NE(some.output.find("skipped 0001.png: it is an identical copy of 0001 copy.png"), std::string::npos)
      << some.output;

  const fs::path copies = dir.Path() / "copies";
  fs::create_directories(copies);
  for (const char* name : {"a.png", "b.png", "c.png", "d.png"}) fs::copy_file(kSmallImages / "0000.png", copies / name);
  const CliResult alone = RunParallax(Reconstruct(copies, dir.Path() / "ws2"));
  ExpectFailure(alone, 2, "1 readable image(s)");
  EXPECT_NE(alone.output.find("d.png is an identical copy of a.png"), std::string::npos) << alone.output;
}

// The courtyard's arc of photos in the forms cameras and editors write, each form twice, in a
// folder whose path has spaces and non-ASCII letters: COLMAP reads none of the converted forms
// as they are (its 16-bit TIFFs fail outright), and ignores EXIF orientation. (The small scene
// is too fragile for this: re-encoding alone makes its mapper fail on most runs.)
TEST(ReconstructCli, PhotosInEveryFormACameraWritesAreReconstructed) {
  const fs::path& courtyard = kCourtyardImages;
  const TempDir dir;
  const fs::path photos = dir.Path() / "Fotos – Innenhof";
  fs::create_directories(photos);
  using Edit = std::function<OIIO::ImageBuf(const OIIO::ImageBuf&)>;
  const Edit same = [](const OIIO::ImageBuf& image) { return image; };
  const Edit grey = [](const OIIO::ImageBuf& image) {
    return OIIO::ImageBufAlgo::channel_sum(image, {0.2126f, 0.7152f, 0.0722f});
  };
  const Edit with_alpha = [](const OIIO::ImageBuf& image) {
    return OIIO::ImageBufAlgo::channels(image, 4, {0, 1, 2, -1}, {0, 0, 0, 1.0f});
  };
  const Edit upside_down = [](const OIIO::ImageBuf& image) { return OIIO::ImageBufAlgo::rotate180(image); };
  struct Form {
    std::string suffix;
    OIIO::TypeDesc type;
    Edit edit;
    int orientation;
    std::string format;  // Of the content, when it is not what the suffix says.
  };
  const std::vector<Form> forms = {{" as taken.png", OIIO::TypeDesc::UINT8, same, 1, ""},
                                   {" 16 bit.tif", OIIO::TypeDesc::UINT16, same, 1, ""},
                                   {" grau.jpg", OIIO::TypeDesc::UINT8, grey, 1, ""},
                                   {" alpha.png", OIIO::TypeDesc::UINT8, with_alpha, 1, ""},
                                   {" really a png.jpg", OIIO::TypeDesc::UINT8, same, 1, "png"},
                                   {" upside down.jpg", OIIO::TypeDesc::UINT8, upside_down, 3, ""},
                                   {" 16 bit.png", OIIO::TypeDesc::UINT16, same, 1, ""},
                                   {" é.bmp", OIIO::TypeDesc::UINT8, same, 1, ""}};
  for (int i = 0; i < kArcPhotos; ++i) {
    const std::string stem = ArcStem(i);
    const Form& form = forms[static_cast<size_t>(i) % forms.size()];
    OIIO::ImageBuf image = form.edit(OIIO::ImageBuf((courtyard / (stem + ".png")).string()));
    image.specmod().attribute("Orientation", form.orientation);
    ASSERT_TRUE(image.write((photos / (stem + form.suffix)).string(), form.type, form.format)) << image.geterror();
  }

  const fs::path workspace = dir.Path() / "ws ä";
  const CliResult result = RunParallax(Reconstruct(photos, workspace, "--no-depth --quality fast"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("registered 16/16 photos"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("14 photo(s) converted"), std::string::npos) << result.output;
  std::ifstream report_file(workspace / "report.json");
  const auto notes = nlohmann::json::parse(report_file)["reconstruct"]["notes"].dump();
  for (const char* reason : {"2 EXIF orientation 3", "2 a png file named .jpg", "2 tiff, uint16", "2 grayscale"}) {
    EXPECT_NE(notes.find(reason), std::string::npos) << reason << " not in " << notes;
  }
  // The photo stored upside down is upright in the workspace: it matches the original there.
  const Image upright = ReadImage(workspace / "images" / (ArcStem(5) + " upside down.jpg"));
  const Image original = ReadImage(courtyard / (ArcStem(5) + ".png"));
  ASSERT_EQ(upright.Pixels().size(), original.Pixels().size());
  double error = 0;
  for (size_t i = 0; i < upright.Pixels().size(); ++i) {
    error += static_cast<double>(std::abs(upright.Pixels()[i] - original.Pixels()[i]));
  }
  EXPECT_LT(error / static_cast<double>(upright.Pixels().size()), 0.01);
  // A second run converts nothing again.
  const CliResult again = RunParallax(Reconstruct(photos, workspace, "--no-depth --quality fast --dry-run"));
  EXPECT_NE(again.output.find("photos       skip"), std::string::npos) << again.output;
}

// A JPEG cut short and a float TIFF with NaN and infinite pixels among the arc's photos: the JPEG
// is set aside, named as the scan finds it, and the others register; the TIFF is used, and
// its non-finite pixels are named with what became of them. Then stages.json is cut short:
// the next run names it and plans every stage again.
TEST(ReconstructCli, ADamagedPhotoIsSetAsideAndADamagedStageCacheNamed) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  for (int i = 0; i < kArcPhotos; ++i) {
    const std::string stem = ArcStem(i);
    OIIO::ImageBuf image((kCourtyardImages / (stem + ".png")).string());
    if (i != 3) {
      ASSERT_TRUE(image.write((photos / (stem + ".png")).string())) << image.geterror();
      continue;
    }
    OIIO::ImageBuf hostile;
    ASSERT_TRUE(OIIO::ImageBufAlgo::copy(hostile, image, OIIO::TypeDesc::FLOAT));
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float values[3][3] = {{nan, nan, nan}, {inf, inf, inf}, {-inf, -inf, -inf}};
    for (int k = 0; k < 3; ++k) hostile.setpixel(10 + k, 10, values[k]);
    ASSERT_TRUE(hostile.write((photos / (stem + ".tif")).string(), OIIO::TypeDesc::FLOAT)) << hostile.geterror();
  }
  // A photo of the other side of the ring, its JPEG cut in the middle of the compressed pixels.
  ASSERT_TRUE(OIIO::ImageBuf((kCourtyardImages / "0010.png").string()).write((dir.Path() / "whole.jpg").string()));
  const std::string jpeg = ReadFileBytes(dir.Path() / "whole.jpg");
  const size_t scan = jpeg.find("\xff\xda");
  ASSERT_NE(scan, std::string::npos);
  std::ofstream(photos / "0010.jpg", std::ios::binary)
      .write(jpeg.data(), static_cast<std::streamsize>((scan + jpeg.size()) / 2));

  const fs::path workspace = dir.Path() / "ws";
  const CliResult result = RunParallax(Reconstruct(photos, workspace, "--no-depth --quality fast"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("registered 16/16 photos"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("WARNING: skipped 0010.jpg: it is corrupt or truncated (JPEG error: Premature end"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("WARNING: " + ArcStem(3) + ".tif has non-finite pixels: 3 NaN and 3 -Inf values "
                               "converted to 0 (black), 3 +Inf values to 255 (white)"),
            std::string::npos)
      << result.output;
  const nlohmann::json report = nlohmann::json::parse(ReadFileBytes(workspace / "report.json"))["reconstruct"];
  ASSERT_EQ(report["skipped_files"].size(), 1u);
  EXPECT_EQ(report["skipped_files"][0]["name"], "0010.jpg");

  const std::string stages = ReadFileBytes(workspace / "stages.json");
  std::ofstream(workspace / "stages.json", std::ios::binary).write(stages.data(), static_cast<std::streamsize>(stages.size() / 2));
  const CliResult again = RunParallax(Reconstruct(photos, workspace, "--no-depth --quality fast --dry-run"));
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("WARNING: " + (workspace / "stages.json").string() + " is damaged ("), std::string::npos)
      << again.output;
  EXPECT_NE(again.output.find("no stage counts as done, every stage runs again"), std::string::npos) << again.output;
  EXPECT_NE(again.output.find("features     will run"), std::string::npos) << again.output;
}

// Half the photos resized (another camera, or an editor's export): one camera per size, each
// with the focal length of its size, instead of one per photo.
TEST(ReconstructCli, PhotosOfTwoSizesGetOneCameraPerSize) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "two sizes";
  fs::create_directories(photos);
  for (int i = 0; i < kArcPhotos; ++i) {
    const std::string name = ArcStem(i) + ".png";
    OIIO::ImageBuf image((kCourtyardImages / name).string());
    if (i % 2) image = OIIO::ImageBufAlgo::resize(image, "", 0, OIIO::ROI(0, 480, 0, 360));
    ASSERT_TRUE(image.write((photos / name).string())) << image.geterror();
  }
  const fs::path workspace = dir.Path() / "ws";
  const CliResult result = RunParallax(Reconstruct(photos, workspace, "--no-depth --quality fast"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("registered 16/16 photos"), std::string::npos) << result.output;
  std::ifstream report_file(workspace / "report.json");
  EXPECT_NE(nlohmann::json::parse(report_file)["reconstruct"]["camera_model"].get<std::string>().find("(2 cameras)"),
            std::string::npos);
  const SparseModel model = ReadSparseModel(workspace / "sparse");
  ASSERT_EQ(model.Cameras().size(), 2u);
  for (const Camera& camera : model.Cameras()) {
    // The courtyard was rendered with a 520 px focal length at 640 px wide.
    const double true_focal = 520.0 * static_cast<double>(camera.width) / 640.0;
    EXPECT_NEAR(camera.params[0], true_focal, 0.02 * true_focal) << camera.width << "x" << camera.height;
  }
}

// One photo re-encoded, brightened and blurred: copies no hash catches, with no baseline.
TEST(ReconstructCli, NearIdenticalPhotosExitTwoSayingTheyHaveNoParallax) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "burst";
  fs::create_directories(photos);
  const OIIO::ImageBuf photo((kCourtyardImages / "0000.png").string());
  ASSERT_TRUE(photo.write((photos / "a.png").string()));
  ASSERT_TRUE(photo.write((photos / "b.jpg").string()));
  ASSERT_TRUE(OIIO::ImageBufAlgo::mul(photo, 1.05f).write((photos / "c.png").string()));
  const OIIO::ImageBuf kernel = OIIO::ImageBufAlgo::make_kernel("gaussian", 3, 3);
  ASSERT_TRUE(OIIO::ImageBufAlgo::convolve(photo, kernel).write((photos / "d.png").string()));
  const CliResult result = RunParallax(Reconstruct(photos, dir.Path() / "ws", "--no-depth"));
  ExpectFailure(result, 2, "the photos have no parallax: each of the 6 matched pairs is explained by a homography");
  EXPECT_NE(result.output.find("logs/mapper.log"), std::string::npos) << result.output;
}

TEST(ReconstructCli, PhotosThatShareNoFeaturesExitTwoSayingSo) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "unrelated";
  fs::create_directories(photos);
  for (int seed = 1; seed <= 3; ++seed) {
    OIIO::ImageBuf noise(OIIO::ImageSpec(320, 240, 3, OIIO::TypeDesc::UINT8));
    ASSERT_TRUE(OIIO::ImageBufAlgo::noise(noise, "uniform", 0.0f, 1.0f, false, seed));
    ASSERT_TRUE(noise.write((photos / ("noise" + std::to_string(seed) + ".png")).string()));
  }
  ExpectFailure(RunParallax(Reconstruct(photos, dir.Path() / "ws", "--no-depth")), 2,
                "the photos share no features: no two of the 3 photos have enough matching features");
}

TEST(ReconstructCli, UnwritableWorkspaceExitsTwo) {
  const TempDir dir;
  std::ofstream(dir.Path() / "a_file") << "x";
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "a_file" / "ws")), 2,
                "cannot be created");
}

TEST(ReconstructCli, BadIntrinsicsAndModelsAreUsageErrors) {
  const TempDir dir;
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--intrinsics 1,2")), 1,
                "intrinsics must be f or fx,fy,cx,cy");
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--intrinsics abc")), 1,
                "'abc' is not a number");
  ExpectFailure(
      RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--camera-model FISHEYE9")), 1,
      "unknown camera model 'FISHEYE9'");
}

TEST(ReconstructCli, AVocabularyTreeIsCheckedBeforeColmapAndThenUsedInsteadOfBuilt) {
  const TempDir dir;
  const fs::path missing = dir.Path() / "missing.bin";
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--vocab-tree " + Quote(missing.string()))),
                2, "vocabulary tree " + missing.string() + " does not exist");
  ExpectFailure(RunParallax(Reconstruct(kSmallImages, dir.Path() / "ws", "--vocab-tree " + Quote(dir.Path().string()))),
                2, "vocabulary tree " + dir.Path().string() + " is not a file");
  const fs::path tree = dir.Path() / "tree.bin";
  std::ofstream(tree) << "a tree";
  const CliResult plan = RunParallax(
      Reconstruct(kSmallImages, dir.Path() / "ws", "--matcher retrieval --dry-run --vocab-tree " + Quote(tree.string())));
  EXPECT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_NE(plan.output.find("vocabulary tree skipped: the vocabulary tree " + tree.string() + " is used"),
            std::string::npos)
      << plan.output;
}

TEST(ReconstructCli, ColmapFailingExitsThreeWithItsStatusLastLinesAndLog) {
  const TempDir dir;
  const fs::path photos = dir.Path() / "photos";
  fs::create_directories(photos);
  for (const char* name : {"0000.png", "0001.png", "0002.png", "0003.png"}) fs::copy_file(kSmallImages / name, photos / name);
  // The real colmap, its mapper asked for more matches than any pair has: a failure the
  // photos do not explain.
  const fs::path colmap = dir.Path() / "colmap";
  std::ofstream(colmap) << "#!/bin/sh\n"
                           "if [ \"$1\" = mapper ]; then exec colmap \"$@\" --Mapper.min_num_matches 100000; fi\n"
                           "exec colmap \"$@\"\n";
  fs::permissions(colmap, fs::perms::owner_all);
  const CliResult result = RunParallax(Reconstruct(photos, dir.Path() / "ws", "--colmap " + Quote(colmap.string())));
  ExpectFailure(result, 3, "colmap mapper failed with exit status");
  EXPECT_NE(result.output.find("  | "), std::string::npos) << result.output;  // Log lines.
  EXPECT_NE(result.output.find("mapper.log"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace parallax

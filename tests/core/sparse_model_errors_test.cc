// Sparse models that cannot be read are refused with the file, line and what is wrong: cut
// short, huge counts, missing fields, unknown models, dangling ids, non-finite values.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/sparse_model.h"
#include "tests/core/sparse_model_example.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {
namespace fs = std::filesystem;
using sparse_model_example::MakeModel;
using sparse_model_example::WriteFile;
using sparse_model_example::WriteTextModel;

// The message of the BadInputError that reading `dir` throws; a failure if none is thrown.
std::string ReadError(const fs::path& dir, SparseFormat format) {
  try {
    ReadSparseModel(dir, format);
  } catch (const BadInputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "reading " << dir << " did not throw BadInputError";
  return "";
}

TEST(SparseModelErrors, TruncatedCamerasBinaryNamesTheFile) {
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kBinary);
  const std::string bytes = ReadFileBytes(dir.Path() / "model" / "cameras.bin");
  WriteFile(dir.Path() / "model" / "cameras.bin", bytes.substr(0, bytes.size() - 5));
  const std::string message = ReadError(dir.Path() / "model", SparseFormat::kBinary);
  EXPECT_NE(message.find("cameras.bin"), std::string::npos) << message;
  EXPECT_NE(message.find("truncated in camera 3 of 3"), std::string::npos) << message;
}

// What a fuzzer would try first: no prefix of a valid file may crash or read out of bounds.
TEST(SparseModelErrors, EveryTruncationOfABinaryFileIsReported) {
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kBinary);
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const fs::path path = dir.Path() / "model" / name;
    const std::string bytes = ReadFileBytes(path);
    for (size_t size = 0; size < bytes.size(); ++size) {
      WriteFile(path, bytes.substr(0, size));
      const std::string message = ReadError(dir.Path() / "model", SparseFormat::kBinary);
      EXPECT_NE(message.find(name), std::string::npos) << size << " bytes: " << message;
    }
    WriteFile(path, bytes);
  }
}

TEST(SparseModelErrors, HugeCountIsRefusedBeforeAllocating) {
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kBinary);
  std::string bytes = ReadFileBytes(dir.Path() / "model" / "points3D.bin");
  const uint64_t huge = uint64_t{1} << 60;
  std::memcpy(bytes.data(), &huge, sizeof(huge));
  WriteFile(dir.Path() / "model" / "points3D.bin", bytes);
  const std::string message = ReadError(dir.Path() / "model", SparseFormat::kBinary);
  EXPECT_NE(message.find("points3D.bin: " + std::to_string(huge) + " 3D points"),
            std::string::npos)
      << message;
}

TEST(SparseModelErrors, ImagesTextWithAMissingFieldNamesTheFileAndLine) {
  const TempDir dir;
  const fs::path model = WriteTextModel(dir, "1 PINHOLE 4 3 2 2 2 1.5\n",
                                        "# images\n1 1 0 0 0 0 0 0 1\n\n");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("images.txt line 2: expected IMAGE_ID"), std::string::npos) << message;
}

TEST(SparseModelErrors, WrongCameraParameterCountNamesTheFileAndModel) {
  const TempDir dir;
  const fs::path model = WriteTextModel(dir, "# c\n# c\n# c\n1 PINHOLE 4 3 2 2 2\n", "");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("cameras.txt line 4: expected 4 parameters for PINHOLE, got 3"),
            std::string::npos)
      << message;
}

TEST(SparseModelErrors, UnknownCameraModelNameNamesTheFile) {
  const TempDir dir;
  const fs::path model = WriteTextModel(dir, "1 NOT_A_MODEL 4 3 2 2 2 1.5\n", "");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("cameras.txt line 1"), std::string::npos) << message;
  EXPECT_NE(message.find("NOT_A_MODEL"), std::string::npos) << message;
}

TEST(SparseModelErrors, UnknownCameraModelIdNamesTheFile) {
  const TempDir dir;
  WriteSparseModel(MakeModel(), dir.Path() / "model", SparseFormat::kBinary);
  std::string bytes = ReadFileBytes(dir.Path() / "model" / "cameras.bin");
  const int32_t bad_model = 99;
  std::memcpy(bytes.data() + 8 + 4, &bad_model, sizeof(bad_model));
  WriteFile(dir.Path() / "model" / "cameras.bin", bytes);
  const std::string message = ReadError(dir.Path() / "model", SparseFormat::kBinary);
  EXPECT_NE(message.find("cameras.bin: camera 1 of 3: unknown camera model id 99"),
            std::string::npos)
      << message;
}

TEST(SparseModelErrors, ImageWithAMissingCameraIsRefused) {
  const TempDir dir;
  const fs::path model =
      WriteTextModel(dir, "1 PINHOLE 4 3 2 2 2 1.5\n", "1 1 0 0 0 0 0 0 8 a.jpg\n\n");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("images.txt line 1: camera id 8"), std::string::npos) << message;
}

TEST(SparseModelErrors, DuplicateIdsAreRefused) {
  const TempDir dir;
  const fs::path model =
      WriteTextModel(dir, "1 PINHOLE 4 3 2 2 2 1.5\n1 PINHOLE 4 3 2 2 2 1.5\n", "");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("cameras.txt line 2: duplicate camera id 1"), std::string::npos)
      << message;
}

TEST(SparseModelErrors, NonFiniteValuesAreRefused) {
  const TempDir dir;
  const fs::path model =
      WriteTextModel(dir, "1 PINHOLE 4 3 2 2 2 1.5\n", "1 1 0 0 0 nan 0 0 1 a.jpg\n\n");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("images.txt line 1: non-finite TX 'nan'"), std::string::npos)
      << message;
}

TEST(SparseModelErrors, TrackBeyondTheImagesPointsIsRefused) {
  const TempDir dir;
  const fs::path model =
      WriteTextModel(dir, "1 PINHOLE 4 3 2 2 2 1.5\n", "1 1 0 0 0 0 0 0 1 a.jpg\n1 2 5\n");
  WriteFile(model / "points3D.txt", "5 0 0 1 0 0 0 -1 1 3\n");
  const std::string message = ReadError(model, SparseFormat::kText);
  EXPECT_NE(message.find("3D point 5 track element (1, 3) is beyond"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace parallax

// Replacing a folder built under a scratch name: the new one ends up in place, and the old one
// is never lost before it is.
#include "core/atomic_file.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

// A folder holding one file `name` with `text` in it.
void MakeFolder(const fs::path& folder, const std::string& name, const std::string& text) {
  fs::create_directories(folder);
  WriteFileAtomically(folder / name, text);
}

TEST(ReplaceFolder, TheNewFolderTakesTheOldOnesPlaceAndNothingElseIsLeft) {
  const TempDir dir;
  MakeFolder(dir.Path() / "images", "old.png", "old");
  MakeFolder(dir.Path() / "images.tmp", "new.png", "new");
  ReplaceFolder(dir.Path() / "images.tmp", dir.Path() / "images");
  EXPECT_EQ(ReadFileBytes(dir.Path() / "images" / "new.png"), "new");
  EXPECT_FALSE(fs::exists(dir.Path() / "images" / "old.png"));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.Path())) ++entries;
  EXPECT_EQ(entries, 1);  // No scratch and no trash beside it.
}

TEST(ReplaceFolder, MovesTheFolderInWhereThereWasNone) {
  const TempDir dir;
  MakeFolder(dir.Path() / "scratch", "a.txt", "a");
  ReplaceFolder(dir.Path() / "scratch", dir.Path() / "final");
  EXPECT_EQ(ReadFileBytes(dir.Path() / "final" / "a.txt"), "a");
  EXPECT_FALSE(fs::exists(dir.Path() / "scratch"));
}

TEST(ReplaceFolder, KeepsTheOldFolderWhenTheNewOneIsMissing) {
  const TempDir dir;
  MakeFolder(dir.Path() / "sparse", "cameras.bin", "old");
  EXPECT_THROW(ReplaceFolder(dir.Path() / "missing", dir.Path() / "sparse"), BadInputError);
  EXPECT_EQ(ReadFileBytes(dir.Path() / "sparse" / "cameras.bin"), "old");
}

TEST(ReplaceFolder, RemovesTheTrashOfARunStoppedBetweenTheRenames) {
  const TempDir dir;
  MakeFolder(dir.Path() / ".stereo.trash", "stale.bin", "stale");
  MakeFolder(dir.Path() / "stereo", "old.bin", "old");
  MakeFolder(dir.Path() / "stereo.tmp", "new.bin", "new");
  ReplaceFolder(dir.Path() / "stereo.tmp", dir.Path() / "stereo");
  EXPECT_EQ(ReadFileBytes(dir.Path() / "stereo" / "new.bin"), "new");
  EXPECT_FALSE(fs::exists(dir.Path() / ".stereo.trash"));
}

TEST(RemoveAll, RemovesAFolderWithItsFilesAndAcceptsOneThatIsNotThere) {
  const TempDir dir;
  MakeFolder(dir.Path() / "a" / "b", "c.txt", "c");
  RemoveAll(dir.Path() / "a");
  EXPECT_FALSE(fs::exists(dir.Path() / "a"));
  EXPECT_NO_THROW(RemoveAll(dir.Path() / "a"));
}

}  // namespace
}  // namespace parallax

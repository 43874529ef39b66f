#include "core/workspace_lock.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// The message a lock attempt is refused with; "" when it is granted (and then released).
std::string Refusal(const std::filesystem::path& workspace, LockMode mode) {
  try {
    const WorkspaceLock lock(workspace, mode, "second");
  } catch (const BadInputError& error) {
    return error.what();
  }
  return "";
}

// Each WorkspaceLock opens the file anew, so two in one process exclude each other as two
// processes would (flock locks belong to the open file).
TEST(WorkspaceLock, OneWriterOrManyReaders) {
  const TempDir dir;
  {
    const WorkspaceLock writer(dir.Path(), LockMode::kExclusive, "reconstruct");
    const std::string pid = std::to_string(::getpid());
    EXPECT_NE(Refusal(dir.Path(), LockMode::kExclusive).find("is being written by reconstruct (pid " + pid + ")"),
              std::string::npos);
    EXPECT_NE(Refusal(dir.Path(), LockMode::kShared).find("is being written by reconstruct (pid " + pid + ")"),
              std::string::npos);
  }
  EXPECT_EQ(Refusal(dir.Path(), LockMode::kExclusive), "") << "released with its owner";
  {
    const WorkspaceLock reader(dir.Path(), LockMode::kShared, "render");
    EXPECT_EQ(Refusal(dir.Path(), LockMode::kShared), "");
    EXPECT_NE(Refusal(dir.Path(), LockMode::kExclusive).find("is being read by another parallax process"),
              std::string::npos);
    WorkspaceLock upgrading(dir.Path(), LockMode::kShared, "render");
    EXPECT_THROW(upgrading.MakeExclusive(), BadInputError) << "another reader is in the way";
  }
  WorkspaceLock alone(dir.Path(), LockMode::kShared, "render");
  alone.MakeExclusive();
  EXPECT_NE(Refusal(dir.Path(), LockMode::kShared).find("is being written by render"), std::string::npos);
}

TEST(WorkspaceLock, AMissingWorkspaceIsNamed) {
  const TempDir dir;
  EXPECT_NE(Refusal(dir.Path() / "missing", LockMode::kShared).find("does not exist"), std::string::npos);
  EXPECT_NE(Refusal(dir.Path() / "missing", LockMode::kExclusive).find("does not exist"), std::string::npos);
}

TEST(WorkspaceLock, AReadOnlyWorkspaceCanBeReadButNotWritten) {
  const TempDir dir;
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  const std::filesystem::path read_only = dir.Path() / "read-only";
  std::filesystem::create_directories(read_only);
  ::chmod(read_only.c_str(), 0555);
  EXPECT_EQ(Refusal(read_only, LockMode::kShared), "");
  EXPECT_NE(Refusal(read_only, LockMode::kExclusive).find("cannot open its lock file"), std::string::npos);
  ::chmod(read_only.c_str(), 0755);
}

}  // namespace
}  // namespace parallax

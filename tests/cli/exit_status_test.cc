// The exit code each failure gets (apps/exit_status.h): the user's command line, the user's
// files, an external tool and parallax's own bugs are told apart.
#include "apps/exit_status.h"

#include <filesystem>
#include <new>
#include <stdexcept>
#include <system_error>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace parallax {
namespace {

template <typename Exception>
ExitStatus StatusOf(const Exception& exception) {
  return ExitStatusOf(std::make_exception_ptr(exception));
}

TEST(ExitStatus, TheUsersCommandLineIsOne) {
  const ExitStatus status = StatusOf(UsageError("--size 8x8: expected WxH with 16..16384 pixels per side"));
  EXPECT_EQ(status.code, 1);
  EXPECT_EQ(status.message, "--size 8x8: expected WxH with 16..16384 pixels per side");
}

TEST(ExitStatus, TheUsersFilesAreTwo) {
  EXPECT_EQ(StatusOf(BadInputError("photos/a.jpg: cannot read the image")).code, 2);
  const ExitStatus filesystem = StatusOf(std::filesystem::filesystem_error(
      "cannot create", std::filesystem::path("/ws/depth"), std::make_error_code(std::errc::permission_denied)));
  EXPECT_EQ(filesystem.code, 2);
  EXPECT_NE(filesystem.message.find("/ws/depth"), std::string::npos) << filesystem.message;
  try {
    (void)nlohmann::json::parse("{\"views\": ");
    FAIL() << "the JSON parsed";
  } catch (...) {
    const ExitStatus json = ExitStatusOf(std::current_exception());
    EXPECT_EQ(json.code, 2);
    EXPECT_EQ(json.message.rfind("malformed JSON: ", 0), 0u) << json.message;
  }
}

TEST(ExitStatus, AnExternalToolIsThree) {
  EXPECT_EQ(StatusOf(ToolError("colmap mapper failed: see ws/logs/mapper.log")).code, 3);
}

TEST(ExitStatus, BugsAndTheMachineAreFourAndSaySo) {
  const ExitStatus bug = StatusOf(InternalError("Blend: warp buffers of different sizes"));
  EXPECT_EQ(bug.code, 4);
  EXPECT_EQ(bug.message.rfind("internal error: Blend: warp buffers of different sizes", 0), 0u) << bug.message;
  // std::invalid_argument is a standard library's or a bug's, never the user's command line.
  EXPECT_EQ(StatusOf(std::invalid_argument("stod")).code, 4);
  EXPECT_EQ(StatusOf(std::runtime_error("the GL program does not link")).code, 4);
  const ExitStatus memory = StatusOf(std::bad_alloc());
  EXPECT_EQ(memory.code, 4);
  EXPECT_EQ(memory.message, "out of memory");
  EXPECT_EQ(ExitStatusOf(std::make_exception_ptr(42)).code, 4);
}

}  // namespace
}  // namespace parallax

#pragma once
// Exit codes by whose fault a command failed (docs/design.md, "Exit codes").
#include <exception>
#include <string>

namespace parallax {

constexpr int kExitUsage = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitToolFailed = 3;
constexpr int kExitInternal = 4;

struct ExitStatus {
  int code = kExitInternal;
  std::string message;  // What `main` prints after "error: ".
};

// The exit code and message for `error`: UsageError 1; BadInputError, filesystem and JSON errors
// (paths and JSON come from the user) 2; ToolError 3; anything else, a bug or the machine, 4.
ExitStatus ExitStatusOf(const std::exception_ptr& error);

}  // namespace parallax

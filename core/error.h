#pragma once
// Exceptions thrown at the boundaries of parallax. The CLI maps each to an exit code
// (docs/design.md): usage 1, bad input 2, external tool 3.
#include <stdexcept>
#include <string>

namespace parallax {

// The user's input is unusable: a missing or corrupt file, an unwritable folder, a malformed
// scene. The message names the file and what is wrong.
class BadInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An external tool (colmap) is missing or failed. The message names the tool and how to
// install it, or the log file to read.
class ToolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace parallax

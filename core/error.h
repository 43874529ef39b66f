#pragma once
// Exceptions by whose fault they are. The CLI maps each to an exit code (docs/design.md):
// usage 1, bad input 2, external tool 3, internal 4.
//
// A function that checks the values its caller passes throws InternalError: a bad value there
// is a bug in the caller. Code that reads a file checks what it reads before passing it on
// (Camera::Problem, for one) and throws BadInputError naming the file. Where only computing
// with the values can tell (a lens distortion that cannot be inverted), the function throws
// BadInputError and the code that read the values adds the file's name.
#include <stdexcept>
#include <string>

namespace parallax {

// The command line asks for what parallax refuses: an option's value outside its range, options
// that exclude each other. The message names the option and what was expected.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

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

// A caller broke a documented precondition (images of different sizes, a NaN in an image being
// written, a distorted camera where a pinhole one is required): a bug in parallax, never the
// user's fault.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace parallax

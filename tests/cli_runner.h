#pragma once
// Runs the real parallax executable and captures its exit code and output (stdout + stderr).
#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

#include "tests/test_paths.h"

namespace parallax {

struct CliResult {
  int exit_code = -1;
  std::string output;
};

// Runs a shell command line, capturing stdout and stderr together.
inline CliResult RunCommand(const std::string& command) {
  CliResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  size_t count;
  while ((count = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.output.append(buffer.data(), count);
  }
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// `arguments` is appended to the executable as shell words (quote paths with spaces).
inline CliResult RunParallax(const std::string& arguments, const std::string& environment = "") {
  return RunCommand(environment + " '" + ParallaxExecutable() + "' " + arguments);
}

inline std::string Quote(const std::string& path) { return "'" + path + "'"; }

}  // namespace parallax

#pragma once
// Runs an external program with its output (stdout and stderr merged) delivered line by line.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace parallax {

struct ProcessResult {
  int exit_code = 0;  // The program's exit status; 128 + N when killed by signal N.
  long peak_memory_kb = 0;  // The child's peak resident set size (its own, not its children's).
};

// Runs argv[0] (a path or a name looked up on PATH) with `extra_environment` entries
// ("NAME=value") added to this process's environment. Calls `on_line` for every line of output
// as it arrives. Throws std::runtime_error if the program cannot be started.
ProcessResult RunProcess(const std::vector<std::string>& argv,
                         const std::vector<std::string>& extra_environment,
                         const std::function<void(std::string_view line)>& on_line);

// The executable `name` resolves to on PATH (or `name` itself when it contains a '/' and is
// executable); empty when there is none.
std::string FindExecutable(const std::string& name);

}  // namespace parallax

#pragma once
// The real `colmap` CLI (Debian's COLMAP 3.8, CPU build), run as a subprocess: its full log
// goes to a file, its progress lines to a Progress, and a failure becomes a ToolError that
// names the command, the exit status, the last log lines and the log file.
#include <filesystem>
#include <string>
#include <vector>

#include "core/progress.h"

namespace parallax {

class Colmap {
 public:
  // Looks `executable` up (a path, or a name on PATH; empty means "colmap"). Throws ToolError
  // saying how to install COLMAP when it is not there.
  explicit Colmap(const std::string& executable = "");

  const std::string& Executable() const { return executable_; }

  // Runs `colmap <command> <arguments...>`, appending its output to `log_path`, and reports
  // progress under `stage` as COLMAP prints it ("Processed file [3/12]", "Registering image #4
  // (5)", ...). `num_images` is the total for commands that count registered images.
  // Throws ToolError if colmap exits with a non-zero status.
  void Run(const std::string& command, const std::vector<std::string>& arguments,
           const std::filesystem::path& log_path, std::string_view stage, int num_images,
           Progress& progress) const;

 private:
  std::string executable_;
};

// Progress COLMAP reports in one output line: {done, total}, or {-1, -1} when the line says
// nothing about progress. Exposed for tests.
struct ColmapProgress {
  int64_t done = -1;
  int64_t total = -1;
};
ColmapProgress ParseColmapProgress(std::string_view line, int num_images);

}  // namespace parallax

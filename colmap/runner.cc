#include "colmap/runner.h"

#include <deque>
#include <fstream>
#include <regex>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory.h"
#include "colmap/subprocess.h"

namespace parallax {
namespace {

constexpr int kLogLinesInErrors = 8;

int64_t ToInt(const std::ssub_match& match) { return std::stoll(match.str()); }

}  // namespace

Colmap::Colmap(const std::string& executable) {
  const std::string name = executable.empty() ? "colmap" : executable;
  executable_ = FindExecutable(name);
  if (executable_.empty()) {
    throw ToolError("colmap not found (" + name +
                    "): install it with 'apt-get install colmap' (scripts/install-deps does), "
                    "or pass --colmap /path/to/colmap");
  }
}

ColmapProgress ParseColmapProgress(std::string_view line_view, int num_images) {
  static const std::regex kFile(R"(Processed file \[(\d+)/(\d+)\])");
  static const std::regex kBlock(R"(Matching block \[(\d+)/(\d+), (\d+)/(\d+)\])");
  static const std::regex kImage(R"((?:Matching|Undistorting) image \[(\d+)/(\d+)\])");
  static const std::regex kRegistered(R"((?:Registering|Triangulating) image #\d+ \((\d+)\))");
  const std::string line(line_view);
  std::smatch match;
  if (std::regex_search(line, match, kFile) || std::regex_search(line, match, kImage)) {
    return {ToInt(match[1]), ToInt(match[2])};
  }
  if (std::regex_search(line, match, kBlock)) {
    const int64_t row = ToInt(match[1]), rows = ToInt(match[2]);
    const int64_t column = ToInt(match[3]), columns = ToInt(match[4]);
    return {(row - 1) * columns + column, rows * columns};
  }
  if (std::regex_search(line, match, kRegistered)) return {ToInt(match[1]), num_images};
  return {};
}

void Colmap::Run(const std::string& command, const std::vector<std::string>& arguments,
                 const std::filesystem::path& log_path, std::string_view stage, int num_images,
                 Progress& progress) const {
  std::filesystem::create_directories(log_path.parent_path());
  std::ofstream log(log_path, std::ios::app);
  if (!log) throw BadInputError("cannot write the log " + log_path.string());
  std::vector<std::string> argv = {executable_, command};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  log << "$";
  for (const std::string& argument : argv) log << " " << argument;
  log << "\n";

  std::deque<std::string> last_lines;
  const ProcessResult result = RunProcess(
      argv, {"QT_QPA_PLATFORM=offscreen"}, [&](std::string_view line) {
        log << line << "\n";
        last_lines.emplace_back(line);
        if (last_lines.size() > kLogLinesInErrors) last_lines.pop_front();
        const ColmapProgress step = ParseColmapProgress(line, num_images);
        if (step.done >= 0) progress.Update(stage, step.done, step.total);
      });
  log.flush();
  NoteChildPeakMemory(result.peak_memory_kb);
  if (result.exit_code != 0) {
    // A full disk is the user's to fix, not colmap's failure; its log may not even say so.
    const std::string disk_full = DiskFullReason(log_path.parent_path());
    if (!disk_full.empty()) {
      throw BadInputError("colmap " + command + " could not write its output: " + disk_full);
    }
    std::string message = "colmap " + command + " failed with exit status " +
                          std::to_string(result.exit_code) + "; last lines of its log:\n";
    for (const std::string& line : last_lines) message += "  | " + line + "\n";
    message += "full log: " + log_path.string();
    throw ToolError(message);
  }
}

}  // namespace parallax

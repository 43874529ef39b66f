#pragma once
// The bench's outputs: bench.csv, error_vs_time.png (gnuplot) and report.md.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace parallax {

// One (stage, method, setting) run: its metrics by name and its cost.
struct BenchRow {
  std::string stage;    // sfm, depth, render, shadows.
  std::string method;   // parallax, colmap, sgbm, naive, ...
  std::string setting;  // The knob values, e.g. "quality=balanced sources=5".
  std::map<std::string, double> metrics;
  double time = 0;        // The stage's own time, in its BenchStage::time_label unit.
  double wall_s = 0;      // Wall time of the child process.
  double peak_mb = 0;     // Peak resident memory of the child process.
  bool baseline = false;  // A baseline to beat, not a parallax setting.
};

// How a stage's rows are plotted and judged.
struct BenchStage {
  std::string name;
  std::string error_metric;  // The metric plotted against time.
  std::string error_label;
  bool higher_is_better = false;
  std::string time_label;
};

struct Machine {
  std::string cpu;
  int cores = 0;
};
Machine DescribeMachine();

// Writes bench.csv, plots error_vs_time.png with gnuplot (when gnuplot is installed; says
// so in the report otherwise) and report.md, all into `out_dir`. `leave_out` lines become
// the report's "Leaving out what a scene does not need" section.
void WriteBenchReport(const std::filesystem::path& out_dir, const std::vector<BenchRow>& rows,
                      const std::vector<BenchStage>& stages, const Machine& machine,
                      const std::vector<std::string>& leave_out, double total_seconds);

}  // namespace parallax

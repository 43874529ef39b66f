#include "bench/bench_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "colmap/subprocess.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

std::string Number(double value) {
  if (!std::isfinite(value)) return "";
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", value);
  return text;
}

// Metric names in first-seen order across all rows (the CSV columns).
std::vector<std::string> MetricColumns(const std::vector<BenchRow>& rows) {
  std::vector<std::string> columns;
  for (const BenchRow& row : rows) {
    for (const auto& [name, value] : row.metrics) {
      if (std::find(columns.begin(), columns.end(), name) == columns.end()) columns.push_back(name);
    }
  }
  return columns;
}

std::string TimeUnit(const std::string& stage, const std::vector<BenchStage>& stages) {
  for (const BenchStage& known : stages) {
    if (known.name == stage) return known.time_label;
  }
  return "s";
}

// A CSV field (RFC 4180): quoted, with quotes doubled, when it holds a comma or a quote.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string Csv(const std::vector<BenchRow>& rows, const std::vector<BenchStage>& stages,
                const Machine& machine) {
  const std::vector<std::string> columns = MetricColumns(rows);
  std::string csv = "stage,method,setting,baseline";
  for (const std::string& column : columns) csv += "," + column;
  csv += ",time,time_unit,wall_s,peak_mb,cpu,cores\n";
  for (const BenchRow& row : rows) {
    std::vector<std::string> fields = {row.stage, row.method, row.setting, row.baseline ? "1" : "0"};
    for (const std::string& column : columns) {
      const auto found = row.metrics.find(column);
      fields.push_back(found == row.metrics.end() ? std::string() : Number(found->second));
    }
    for (const std::string& field :
         {Number(row.time), TimeUnit(row.stage, stages), Number(row.wall_s), Number(row.peak_mb),
          machine.cpu, std::to_string(machine.cores)}) {
      fields.push_back(field);
    }
    for (size_t i = 0; i < fields.size(); ++i) csv.append(i ? "," : "").append(CsvField(fields[i]));
    csv.append("\n");
  }
  return csv;
}

// Rows of one stage that have its error metric and a time.
std::vector<const BenchRow*> Plottable(const std::vector<BenchRow>& rows, const BenchStage& stage) {
  std::vector<const BenchRow*> result;
  for (const BenchRow& row : rows) {
    if (row.stage == stage.name && row.metrics.count(stage.error_metric) && row.time > 0) {
      result.push_back(&row);
    }
  }
  return result;
}

double Error(const BenchRow& row, const BenchStage& stage) {
  return row.metrics.at(stage.error_metric);
}

bool Better(double a, double b, const BenchStage& stage) {
  return stage.higher_is_better ? a > b : a < b;
}

// The runs no other run beats on both error and time, fastest first.
std::vector<const BenchRow*> ParetoFront(const std::vector<const BenchRow*>& rows,
                                         const BenchStage& stage) {
  std::vector<const BenchRow*> sorted = rows;
  std::sort(sorted.begin(), sorted.end(),
            [](const BenchRow* a, const BenchRow* b) { return a->time < b->time; });
  std::vector<const BenchRow*> front;
  for (const BenchRow* row : sorted) {
    if (front.empty() || Better(Error(*row, stage), Error(*front.back(), stage), stage)) {
      front.push_back(row);
    }
  }
  return front;
}

// The recommended setting: the fastest parallax run on the Pareto front whose error is within
// 5% (relative) of the best parallax error.
const BenchRow* Recommended(const std::vector<const BenchRow*>& rows, const BenchStage& stage) {
  std::vector<const BenchRow*> ours;
  for (const BenchRow* row : rows) {
    if (!row->baseline) ours.push_back(row);
  }
  if (ours.empty()) return nullptr;
  double best = Error(*ours.front(), stage);
  for (const BenchRow* row : ours) {
    if (Better(Error(*row, stage), best, stage)) best = Error(*row, stage);
  }
  for (const BenchRow* row : ParetoFront(ours, stage)) {
    const double gap = std::abs(Error(*row, stage) - best);
    if (gap <= 0.05 * std::abs(best) + 1e-12) return row;
  }
  return ours.front();
}

std::string PlotScript(const fs::path& out_dir, const std::vector<BenchStage>& stages,
                       const std::vector<BenchRow>& rows) {
  std::ostringstream script;
  script << "set terminal pngcairo size " << 470 * stages.size() << ",420 font 'sans,10'\n"
         << "set output '" << (out_dir / "error_vs_time.png").string() << "'\n"
         << "set multiplot layout 1," << stages.size() << "\n"
         << "set logscale x\nset grid\nset key top outside horizontal center\nset offsets graph 0.05, graph 0.05, graph 0.08, graph 0.08\n"
         << "set datafile separator '\\t'\n";
  for (const BenchStage& stage : stages) {
    const std::vector<const BenchRow*> rows_of_stage = Plottable(rows, stage);
    std::ofstream points(out_dir / ("plot_" + stage.name + ".dat"));
    for (const BenchRow* row : rows_of_stage) {
      points << row->time << "\t" << Error(*row, stage) << "\t" << (row->baseline ? 1 : 0)
             << "\t" << row->method << " " << row->setting << "\n";
    }
    std::ofstream front(out_dir / ("plot_" + stage.name + "_front.dat"));
    for (const BenchRow* row : ParetoFront(rows_of_stage, stage)) {
      front << row->time << "\t" << Error(*row, stage) << "\n";
    }
    script << "set title '" << stage.name << "'\nset xlabel '" << stage.time_label
           << " (log)'\nset ylabel '" << stage.error_label << "'\n"
           << "plot '" << (out_dir / ("plot_" + stage.name + ".dat")).string()
           << "' using 1:($3==0?$2:1/0) with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'parallax', "
           << "'' using 1:($3==1?$2:1/0) with points pt 5 ps 1.4 lc rgb '#d62728' title 'baseline', "
           << "'" << (out_dir / ("plot_" + stage.name + "_front.dat")).string()
           << "' using 1:2 with lines lw 2 lc rgb '#2ca02c' title 'Pareto front'\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

std::string Table(const std::vector<BenchRow>& rows, const BenchStage& stage) {
  std::ostringstream table;
  table << "| method | setting | " << stage.error_label << " | other metrics | " << stage.time_label
        << " | wall s | peak MB |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const BenchRow& row : rows) {
    if (row.stage != stage.name) continue;
    std::string others;
    for (const auto& [name, value] : row.metrics) {
      if (name != stage.error_metric) others += (others.empty() ? "" : ", ") + name + " " + Number(value);
    }
    const auto error = row.metrics.find(stage.error_metric);
    table << "| " << row.method << (row.baseline ? " (baseline)" : "") << " | " << row.setting
          << " | " << (error == row.metrics.end() ? "-" : Number(error->second)) << " | " << others
          << " | " << Number(row.time) << " | " << Number(row.wall_s) << " | "
          << Number(row.peak_mb) << " |\n";
  }
  return table.str();
}

// One paragraph per stage: the recommended setting, the spread of the trade-off, and how the
// recommended run compares with each baseline.
std::string Paragraph(const std::vector<BenchRow>& rows, const BenchStage& stage) {
  const std::vector<const BenchRow*> plottable = Plottable(rows, stage);
  const BenchRow* recommended = Recommended(plottable, stage);
  if (!recommended) return "No parallax run of this stage produced its metric.\n";
  std::ostringstream text;
  const std::vector<const BenchRow*> front = ParetoFront(plottable, stage);
  text << "**Recommended: " << recommended->method << " " << recommended->setting << "** ("
       << stage.error_label << " " << Number(Error(*recommended, stage)) << " at "
       << Number(recommended->time) << " " << stage.time_label
       << "): the fastest run on the Pareto front within 5% of the best parallax error. The front has "
       << front.size() << " of " << plottable.size() << " runs, from "
       << Number(front.front()->time) << " to " << Number(front.back()->time) << " "
       << stage.time_label << ".";
  for (const BenchRow* row : plottable) {
    if (!row->baseline) continue;
    text << " Against the baseline " << row->method << " " << row->setting << " ("
         << Number(Error(*row, stage)) << " at " << Number(row->time) << "): parallax "
         << (Better(Error(*recommended, stage), Error(*row, stage), stage) ? "is better" : "is worse")
         << " by " << Number(std::abs(Error(*recommended, stage) - Error(*row, stage)))
         << " and takes " << Number(recommended->time / row->time) << "x its time.";
  }
  text << "\n";
  return text.str();
}

}  // namespace

Machine DescribeMachine() {
  Machine machine;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      machine.cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  std::replace(machine.cpu.begin(), machine.cpu.end(), '"', '\'');
  machine.cores = static_cast<int>(std::thread::hardware_concurrency());
  return machine;
}

void WriteBenchReport(const fs::path& out_dir, const std::vector<BenchRow>& rows,
                      const std::vector<BenchStage>& stages, const Machine& machine,
                      const std::vector<std::string>& leave_out, double total_seconds) {
  WriteFileAtomically(out_dir / "bench.csv", Csv(rows, stages, machine));
  bool plotted = false;
  if (!FindExecutable("gnuplot").empty()) {
    WriteFileAtomically(out_dir / "error_vs_time.gp", PlotScript(out_dir, stages, rows));
    const ProcessResult result = RunProcess(
        {"gnuplot", (out_dir / "error_vs_time.gp").string()}, {}, [](std::string_view) {});
    plotted = result.exit_code == 0;
  }
  std::ostringstream report;
  report << "# parallax bench\n\nMachine: " << machine.cpu << ", " << machine.cores
         << " cores. Whole bench: " << Number(total_seconds) << " s. Raw numbers: `bench.csv`.\n\n";
  report << (plotted ? "![error against run time](error_vs_time.png)\n\n"
                     : "(gnuplot is not installed: no plot; `apt-get install gnuplot-nox`.)\n\n");
  for (const BenchStage& stage : stages) {
    report << "## " << stage.name << "\n\n" << Paragraph(rows, stage) << "\n" << Table(rows, stage)
           << "\n";
  }
  report << "## Leaving out what a scene does not need\n\n";
  for (const std::string& line : leave_out) report << "- " << line << "\n";
  WriteFileAtomically(out_dir / "report.md", report.str());
}

}  // namespace parallax

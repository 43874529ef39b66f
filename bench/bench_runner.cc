#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_runner.h"

#include "core/atomic_file.h"
#include "core/elapsed.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "colmap/subprocess.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

struct ChildRun {
  double wall_s = 0;
  double peak_mb = 0;
  std::string output;
};

class Bench {
 public:
  Bench(fs::path scene, fs::path out, BenchGrid grid)
      : scene_{std::move(scene)}, out_(std::move(out)), grid_(grid) {
    self_ = fs::read_symlink("/proc/self/exe").string();
    real_ = !fs::is_directory(scene_.Training().depth);
    fs::create_directories(out_ / "logs");
  }

  // Runs one child to completion, its output in logs/<log>.log. Throws ToolError when it fails.
  ChildRun Run(const std::string& log, const std::vector<std::string>& argv) {
    std::fprintf(stderr, "bench: %s ...", log.c_str());
    std::fflush(stderr);
    ChildRun run;
    std::ofstream log_file(out_ / "logs" / (log + ".log"));
    const auto start = std::chrono::steady_clock::now();
    const ProcessResult result = RunProcess(argv, {}, [&](std::string_view line) {
      log_file << line << "\n";
      run.output.append(line).append("\n");
    });
    run.wall_s = SecondsSince(start);
    run.peak_mb = static_cast<double>(result.peak_memory_kb) / 1024.0;
    std::fprintf(stderr, " %.1f s\n", run.wall_s);
    if (result.exit_code != 0) {
      throw ToolError("bench: " + argv[0] + " " + (argv.size() > 1 ? argv[1] : "") +
                      " failed with exit status " + std::to_string(result.exit_code) + "; see " +
                      (out_ / "logs" / (log + ".log")).string());
    }
    return run;
  }

  ChildRun Parallax(const std::string& log, std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), self_);
    return Run(log, arguments);
  }

  // `parallax evaluate` of a workspace; its JSON, and in `run` (when given) the child's cost.
  nlohmann::json Evaluate(const std::string& log, const fs::path& workspace,
                          std::vector<std::string> flags, ChildRun* run = nullptr) {
    const fs::path json = out_ / "logs" / (log + ".json");
    std::vector<std::string> arguments = {"evaluate", workspace.string(), "--gt",
                                          scene_.root.string(), "--json", json.string()};
    arguments.insert(arguments.end(), flags.begin(), flags.end());
    const ChildRun child = Parallax(log, arguments);
    if (run != nullptr) *run = child;
    return nlohmann::json::parse(ReadFileBytes(json));
  }

  void StructureFromMotion();
  void Depth();
  void Render();
  void Shadows();
  void LeaveOut();

  const fs::path& Out() const { return out_; }
  // Real photos: ground-truth cameras and held-out photos, no ground-truth depth.
  bool Real() const { return real_; }
  bool Smoke() const { return grid_ == BenchGrid::kSmoke; }
  std::vector<BenchRow> rows;
  std::vector<std::string> leave_out;

 private:
  fs::path Images() const { return scene_.Training().images; }
  fs::path KnownWorkspace() const { return out_ / "depth_base"; }

  SceneFolder scene_;
  fs::path out_;
  std::string self_;
  BenchGrid grid_;
  bool real_ = false;
};

// The mean share of each view's pixels whose depth survived the geometric filter (the depth
// section of report.json).
double MeanGeometricShare(const nlohmann::json& depth) {
  double sum = 0;
  for (const nlohmann::json& view : depth.at("views")) sum += view.at("geometric_share").get<double>();
  return depth.at("views").empty() ? 0.0 : sum / static_cast<double>(depth.at("views").size());
}

double At(const nlohmann::json& json, const std::string& section, const std::string& key,
          const std::string& sub = "") {
  const nlohmann::json& value = json.at(section).at(key);
  return sub.empty() ? value.get<double>() : value.at(sub).get<double>();
}

void Bench::StructureFromMotion() {
  const std::vector<std::string> qualities =
      Smoke() ? std::vector<std::string>{"fast"} : std::vector<std::string>{"fast", "balanced"};
  for (const std::string& quality : qualities) {
    const fs::path workspace = out_ / ("sfm_" + quality);
    fs::remove_all(workspace);
    const ChildRun run = Parallax("sfm_" + quality, {"reconstruct", Images().string(), workspace.string(),
                                                     "--quality", quality, "--no-depth"});
    const nlohmann::json json = Evaluate("sfm_" + quality + "_eval", workspace, {});
    rows.push_back({"sfm", "parallax", "quality=" + quality,
                    {{"rotation_error_deg", At(json, "poses", "rotation_error_deg", "mean")},
                     {"center_error_rel", At(json, "poses", "center_error_rel", "mean")}},
                    run.wall_s, run.wall_s, run.peak_mb, false});
  }
  // COLMAP's own one-command pipeline, sparse only, on the CPU.
  const fs::path colmap_dir = out_ / "colmap_auto";
  fs::remove_all(colmap_dir);
  fs::create_directories(colmap_dir);
  const ChildRun run = Run("colmap_automatic_reconstructor",
                           {"colmap", "automatic_reconstructor", "--workspace_path", colmap_dir.string(),
                            "--image_path", Images().string(), "--dense", "0", "--use_gpu", "0"});
  const fs::path workspace = out_ / "colmap_auto_ws";
  fs::remove_all(workspace);
  fs::create_directories(workspace);
  fs::copy(colmap_dir / "sparse" / "0", Workspace(workspace).Sparse(), fs::copy_options::recursive);
  const nlohmann::json json = Evaluate("colmap_auto_eval", workspace, {});
  rows.push_back({"sfm", "colmap", "automatic_reconstructor --dense 0",
                  {{"rotation_error_deg", At(json, "poses", "rotation_error_deg", "mean")},
                   {"center_error_rel", At(json, "poses", "center_error_rel", "mean")}},
                  run.wall_s, run.wall_s, run.peak_mb, true});
}

void Bench::Depth() {
  // Triangulation with the true cameras once; every setting starts from a copy, so only the
  // depth stage (and fusion) runs: the stereo is measured apart from SfM.
  const fs::path base = KnownWorkspace();
  const std::string known = scene_.Training().sparse.string();
  fs::remove_all(base);
  Parallax("depth_base", {"reconstruct", Images().string(), base.string(), "--known-cameras", known,
                          "--no-depth"});
  struct Setting {
    std::string id, method, label;
    std::vector<std::string> flags;
    bool baseline = false;
  };
  // Real photos: the working resolution is the knob that matters (docs/depth.md).
  const std::vector<Setting> real_settings = {
      {"fast", "patchmatch", "quality=fast (768 px)", {"--quality", "fast"}},
      {"balanced_768", "patchmatch", "quality=balanced 768 px", {"--mvs-max-size", "768"}},
      {"balanced", "patchmatch", "quality=balanced (1024 px)", {"--quality", "balanced"}},
      {"balanced_1536", "patchmatch", "quality=balanced 1536 px", {"--mvs-max-size", "1536"}},
      {"balanced_full", "patchmatch", "quality=balanced full size", {"--mvs-scale", "1"}},
      {"sgbm", "sgbm", "OpenCV StereoSGBM, rectified pairs", {"--stereo", "sgbm"}, true}};
  const std::vector<Setting> synthetic_settings = {
      {"fast", "patchmatch", "quality=fast sources=3", {"--quality", "fast"}},
      {"balanced", "patchmatch", "quality=balanced sources=5", {"--quality", "balanced"}},
      {"best", "patchmatch", "quality=best sources=7", {"--quality", "best"}},
      {"balanced3", "patchmatch", "quality=balanced sources=3", {"--mvs-sources", "3"}},
      {"balanced7", "patchmatch", "quality=balanced sources=7", {"--mvs-sources", "7"}},
      {"balanced_half", "patchmatch", "quality=balanced sources=5 scale=0.5", {"--mvs-scale", "0.5"}},
      {"fast_half", "patchmatch", "quality=fast sources=3 scale=0.5", {"--quality", "fast", "--mvs-scale", "0.5"}},
      {"sgbm", "sgbm", "OpenCV StereoSGBM, rectified pairs", {"--stereo", "sgbm"}, true}};
  const std::vector<Setting>& settings = real_ ? real_settings : synthetic_settings;
  const SparseModel truth = ReadSparseModel(scene_.Training().sparse);
  const int views = static_cast<int>(truth.Images().size());
  const uint64_t long_side = std::max(truth.Cameras().front().width, truth.Cameras().front().height);
  // The smoke grid: the default, the cheaper resolution the checks compare it with, the baseline.
  const std::set<std::string> smoke_ids = {"balanced", "balanced_half", "fast", "sgbm"};
  for (const Setting& setting : settings) {
    if (setting.id == "balanced_1536" && long_side <= 1536) continue;  // The same as full size.
    if (Smoke() && !smoke_ids.contains(setting.id)) continue;
    const fs::path workspace = out_ / ("depth_" + setting.id);
    fs::remove_all(workspace);
    fs::copy(base, workspace, fs::copy_options::recursive);
    std::vector<std::string> arguments = {"reconstruct", Images().string(), workspace.string(),
                                          "--known-cameras", known, "--no-mesh"};
    arguments.insert(arguments.end(), setting.flags.begin(), setting.flags.end());
    const ChildRun run = Parallax("depth_" + setting.id, arguments);
    const nlohmann::json report = nlohmann::json::parse(ReadFileBytes(Workspace(workspace).Report()));
    const double depth_seconds = report.at("reconstruct").at("timings_s").at("depth").get<double>();
    const nlohmann::json json = Evaluate("depth_" + setting.id + "_eval", workspace, {"--no-align"});
    std::map<std::string, double> metrics = {{"novel_psnr", At(json, "novel", "psnr_mean")},
                                             {"novel_ssim", At(json, "novel", "ssim_mean")}};
    if (real_) {
      // No true depth: the held-out photos, and how much of each depth map its neighbours confirm.
      metrics["novel_psnr_exposure_matched"] = At(json, "novel", "psnr_exposure_matched_mean");
      metrics["consistent_share"] = MeanGeometricShare(report.at("reconstruct").at("depth"));
    } else {
      for (const char* key : {"abs_rel_median", "signed_median", "within_2pct", "completeness"}) {
        metrics[key] = At(json, "depth", key);
      }
    }
    rows.push_back({"depth", setting.method, setting.label, metrics, depth_seconds / views, run.wall_s,
                    run.peak_mb, setting.baseline});
  }
}

void Bench::Render() {
  struct Setting {
    std::string warp;
    int sources;
    std::string fill;
    // More sources while holes or surfaces out of view remain (render --hole-sources).
    int hole_sources = 0;
    bool baseline = false;
    std::string texture_filter = "auto";  // render --texture-filter.
    bool color_gains = true;               // Without: --no-color-gains.
  };
  std::vector<Setting> settings;
  for (const std::string warp : {"mesh", "splat"}) {
    for (int sources : {1, 2, 4, 6}) settings.push_back({warp, sources, "depth-aware"});
  }
  settings.push_back({"mesh", 4, "depth-aware", 1});
  settings.push_back({"mesh", 4, "depth-aware", 2});  // The default.
  settings.push_back({"mesh", 4, "depth-aware", 2, false, "bicubic"});
  settings.push_back({"mesh", 4, "none"});
  settings.push_back({"mesh", 4, "inpaint"});
  settings.push_back({"naive", 1, "inpaint", 0, true});
  if (Smoke()) {
    // The default, its hole sources off, and the baseline.
    settings = {{"mesh", 4, "depth-aware"}, {"mesh", 4, "depth-aware", 2}, {"naive", 1, "inpaint", 0, true}};
  }
  if (real_) {
    // Each evaluation renders full-size held-out photos: the knobs that matter on them only.
    settings = {{"mesh", 2, "depth-aware"}, {"mesh", 4, "depth-aware", 2}, {"mesh", 4, "depth-aware", 2},
                {"naive", 1, "inpaint", 0, true}};
    settings[2].color_gains = false;
  }
  for (const Setting& setting : settings) {
    const bool bicubic = setting.texture_filter != "auto";
    const std::string id = setting.warp + "_k" + std::to_string(setting.sources) + "_h" +
                           std::to_string(setting.hole_sources) + "_" + setting.fill +
                           (bicubic ? "_" + setting.texture_filter : "") +
                           (setting.color_gains ? "" : "_no_gains");
    // Synthetic scenes: from the true depth, the warp apart from the stereo. Real photos have
    // none: from the balanced depth maps, to the held-out photos.
    std::vector<std::string> flags = {"--novel-only", "--sources", std::to_string(setting.sources),
                                      "--hole-sources", std::to_string(setting.hole_sources), "--warp",
                                      setting.warp, "--fill", setting.fill, "--texture-filter",
                                      setting.texture_filter};
    flags.push_back(real_ ? "--no-align" : "--gt-sources");
    if (!setting.color_gains) flags.push_back("--no-color-gains");
    ChildRun run;
    const nlohmann::json json =
        Evaluate("render_" + id, real_ ? out_ / "depth_balanced" : KnownWorkspace(), flags, &run);
    rows.push_back({"render", setting.baseline ? "naive" : "parallax",
                    "warp=" + setting.warp + " K=" + std::to_string(setting.sources) +
                        " hole-sources=" + std::to_string(setting.hole_sources) +
                        " fill=" + setting.fill +
                        (bicubic ? " texture-filter=" + setting.texture_filter : "") +
                        (setting.color_gains ? "" : " no-color-gains"),
                    {{"psnr", At(json, "novel", "psnr_mean")},
                     {"ssim", At(json, "novel", "ssim_mean")},
                     {"psnr_valid", At(json, "novel", "psnr_valid_mean")},
                     {"psnr_exposure_matched", At(json, "novel", "psnr_exposure_matched_mean")},
                     {"hole_ratio", At(json, "novel", "hole_ratio_mean")}},
                    At(json, "novel", "ms_per_view"), run.wall_s, run.peak_mb, setting.baseline});
  }
}

// The number after `key` in a child's output (the first occurrence); throws when it is missing.
double NumberAfter(const std::string& output, const std::string& key, const std::string& log) {
  const size_t at = output.find(key);
  if (at == std::string::npos) throw ToolError("bench: no '" + key + "' in the output of " + log);
  return std::stod(output.substr(at + key.size()));
}

void Bench::Shadows() {
  // The viewer on the balanced workspace's mesh (only the mesh stage runs: depth and fusion are
  // done), from the 30 degree orbit at 1280x720; each frame's shadow mask against Embree's for
  // the mesh it drew. Cast shadows alone rank the settings (see CompareCastShadows).
  const fs::path workspace = out_ / "depth_balanced";
  Parallax("shadows_mesh", {"reconstruct", Images().string(), workspace.string(), "--known-cameras",
                            scene_.Training().sparse.string()});
  fs::create_directories(out_ / "shadows");
  const auto measure = [&](const std::string& mode, const std::string& id, const std::string& setting,
                           const std::vector<std::string>& extra) {
    std::vector<std::string> arguments = {"view", workspace.string(), "--screenshot",
                                          (out_ / "shadows" / (id + ".png")).string(), "--orbit", "30", "--no-cameras",
                                          "--no-grid", "--shadows", mode, "--shadow-iou", "--time-frames", "20"};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    const std::string log = "shadows_" + id;
    const ChildRun run = Parallax(log, arguments);
    std::map<std::string, double> metrics = {{"iou_cast", NumberAfter(run.output, "cast shadows alone: ", log)},
                                             {"iou", NumberAfter(run.output, "shadow IoU against Embree ray tracing: ", log)},
                                             {"ms_still_light", NumberAfter(run.output, "): median ", log)}};
    if (run.output.find("cast shadows on the ground: ") != std::string::npos) {
      metrics["iou_ground"] = NumberAfter(run.output, "cast shadows on the ground: ", log);
      metrics["iou_objects"] = NumberAfter(run.output, "on the objects: ", log);
    }
    rows.push_back({"shadows", "parallax", setting, metrics, NumberAfter(run.output, "light moving: median ", log),
                    run.wall_s, run.peak_mb, false});
  };
  const auto measure_map = [&](int size, int radius) {
    const std::string mode = radius == 0 ? "map" : "pcf";
    measure(mode, mode + std::to_string(radius) + "_" + std::to_string(size),
            mode + (radius > 0 ? " r=" + std::to_string(radius) : "") + " " + std::to_string(size) + "^2",
            {"--shadow-map-size", std::to_string(size), "--pcf-radius", std::to_string(radius)});
  };
  if (Smoke()) {
    // The default, and the coarsest and finest plain maps.
    measure_map(2048, 1);
    for (const int size : {512, 4096}) measure_map(size, 0);
  } else {
    for (const int size : {512, 1024, 2048, 4096}) {
      for (const int radius : {0, 1, 2}) measure_map(size, radius);
    }
  }
  // The other methods of the source texts, which have no knob.
  for (const std::string mode : {"volume", "planar", "blob"}) measure(mode, mode, mode, {});
}

void Bench::LeaveOut() {
  // A second identical run of a finished workspace.
  const fs::path workspace = out_ / "depth_balanced";
  double first = 0;
  for (const BenchRow& row : rows) {
    if (row.stage == "depth" && row.setting == "quality=balanced sources=5") first = row.wall_s;
  }
  const ChildRun again = Parallax("rerun", {"reconstruct", Images().string(), workspace.string(),
                                           "--known-cameras", scene_.Training().sparse.string(), "--no-mesh"});
  char line[256];
  std::snprintf(line, sizeof(line),
                "unchanged inputs: a second identical `reconstruct` (depth balanced) takes %.1f s "
                "instead of %.1f s (%.0fx faster)",
                again.wall_s, first, again.wall_s > 0 ? first / again.wall_s : 0.0);
  leave_out.push_back(line);

  // Rendering from a workspace with only the sparse model: depth only where it is used.
  const fs::path sparse_only = out_ / "leave_out_ws";
  fs::remove_all(sparse_only);
  fs::copy(KnownWorkspace(), sparse_only, fs::copy_options::recursive);
  const SparseModel model = ReadSparseModel(scene_.Training().sparse);
  const std::string a = model.Images().front().name, b = model.Images()[1].name;
  const ChildRun render = Parallax("leave_out_render",
                                   {"render", sparse_only.string(), "--path", "between:" + a + "," + b + ",3",
                                    "--out", (out_ / "leave_out_render").string()});
  for (size_t start = 0, end; (end = render.output.find('\n', start)) != std::string::npos; start = end + 1) {
    const std::string text = render.output.substr(start, end - start);
    if (text.rfind("depth: estimated", 0) == 0 || text.rfind("rendered", 0) == 0) {
      leave_out.push_back("`render --path between:" + a + "," + b + ",3` on a workspace without depth maps: " + text);
    }
  }
  leave_out.push_back("stages skipped, with the reason, are listed per workspace in report.json "
                      "(e.g. depth_balanced/report.json; `reconstruct --dry-run` prints the plan)");
}

}  // namespace

BenchSummary RunBench(const fs::path& scene_dir, const fs::path& out_dir, BenchGrid grid) {
  const SceneFolder scene{scene_dir};
  if (!fs::is_directory(scene.Training().sparse) || !fs::is_directory(scene.Novel().sparse)) {
    throw BadInputError(scene_dir.string() + " has no ground truth (gt/sparse, novel/sparse): "
                        "bench needs a scene folder made by parallax synth, or real photos with "
                        "ground-truth cameras and held-out photos (../shared/datasets)");
  }
  const auto start = std::chrono::steady_clock::now();
  Bench bench(scene_dir, out_dir, grid);
  bench.StructureFromMotion();
  bench.Depth();
  bench.Render();
  if (bench.Real()) {
    bench.leave_out.push_back("shadows: not measured on real photos (no synthetic light to ray trace "
                              "against the viewer's); see the synthetic scene's report");
  } else {
    bench.Shadows();
  }
  bench.LeaveOut();
  std::vector<BenchStage> stages = {
      {"sfm", "rotation_error_deg", "rotation error (deg)", false, "s"},
      {"depth", "within_2pct", "within 2% (share)", true, "s per view"},
      {"render", "psnr", "PSNR (dB)", true, "ms per view"},
      {"shadows", "iou_cast", "cast-shadow IoU vs Embree", true, "ms per frame (light moving)"}};
  if (bench.Real()) {
    stages[1] = {"depth", "novel_psnr", "held-out photo PSNR (dB)", true, "s per view"};
    stages.pop_back();
  }
  BenchSummary summary;
  summary.seconds = SecondsSince(start);
  summary.runs = bench.rows.size();
  WriteBenchReport(bench.Out(), bench.rows, stages, DescribeMachine(), bench.leave_out, summary.seconds);
  return summary;
}

}  // namespace parallax

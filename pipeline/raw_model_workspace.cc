#include "pipeline/raw_model_workspace.h"

#include <algorithm>
#include <utility>

#include "colmap/raw_model.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace parallax {
namespace fs = std::filesystem;

namespace {

// The database and the photos every mapper reads.
std::vector<std::string> MapperInputs(const Workspace& paths, const fs::path& image_dir) {
  return {"--database_path", paths.Database().string(), "--image_path", image_dir.string()};
}

void Append(std::vector<std::string>& arguments, const std::vector<std::string>& more) {
  arguments.insert(arguments.end(), more.begin(), more.end());
}

// The model colmap `command` writes from the model in `input`, through
// Workspace::RefinedModelScratch.
SparseModel RunOnModel(const Colmap& colmap, const Workspace& paths, const fs::path& input,
                       const std::string& command, std::vector<std::string> arguments, const std::string& log_name,
                       int total, Progress& progress) {
  const fs::path output = paths.RefinedModelScratch();
  RemoveAll(output);
  fs::create_directories(output);
  arguments.insert(arguments.end(), {"--input_path", input.string(), "--output_path", output.string()});
  colmap.Run(command, arguments, paths.Log(log_name), log_name, total, progress);
  SparseModel model = ReadSparseModel(output);
  RemoveAll(output);
  return model;
}

}  // namespace

std::vector<std::string> PointTriangulatorArguments(const Workspace& paths, const fs::path& image_dir,
                                                    const fs::path& output) {
  std::vector<std::string> arguments = MapperInputs(paths, image_dir);
  Append(arguments, {"--input_path", paths.KnownModel().string(), "--output_path", output.string()});
  Append(arguments, FixedIntrinsicsArguments());
  return arguments;
}

std::vector<std::string> MapperArguments(const Workspace& paths, const fs::path& image_dir, const fs::path& output,
                                         const fs::path& image_list, bool fixed_intrinsics) {
  std::vector<std::string> arguments = MapperInputs(paths, image_dir);
  Append(arguments, {"--output_path", output.string(), "--image_list_path", image_list.string()});
  if (fixed_intrinsics) Append(arguments, FixedIntrinsicsArguments());
  return arguments;
}

std::vector<std::string> HierarchicalMapperArguments(const Workspace& paths, const fs::path& image_dir,
                                                     const fs::path& output, int cluster_images,
                                                     bool fixed_intrinsics) {
  std::vector<std::string> arguments = MapperInputs(paths, image_dir);
  // The database holds exactly the listed photos, so no image list is needed (nor taken).
  Append(arguments, {"--output_path", output.string(), "--leaf_max_num_images", std::to_string(cluster_images),
                     "--image_overlap", std::to_string(cluster_images / 2)});
  if (fixed_intrinsics) Append(arguments, FixedIntrinsicsArguments());
  return arguments;
}

void RunMapper(const Colmap& colmap, const Workspace& paths, const std::string& command,
               const std::vector<std::string>& arguments, const std::string& name, int num_images,
               Progress& progress) {
  try {
    colmap.Run(command, arguments, paths.Log(name), name, num_images, progress);
  } catch (const ToolError&) {
    // Bad input (exit 2) rather than a tool failure where the matches say why.
    const std::string reason = NoInitialPairReason(paths.Database(), num_images);
    if (reason.empty()) throw;
    throw BadInputError("COLMAP could not reconstruct these photos: " + reason + "; see " +
                        paths.Log(name).string());
  }
}

std::vector<fs::path> ModelDirs(const Workspace& paths) {
  const fs::path models_dir = paths.Models();
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(models_dir)) {
    if (entry.is_directory() && DetectSparseFormat(entry.path())) dirs.push_back(entry.path());
  }
  if (dirs.empty()) {
    throw BadInputError("COLMAP could not reconstruct these photos (no image pair with "
                        "enough matches to start from); see " +
                        paths.Log("mapper").string());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

SparseModel RunOnRawModel(const Colmap& colmap, const Workspace& paths, const std::string& command,
                          std::vector<std::string> arguments, const std::string& log_name, int total,
                          Progress& progress) {
  return RunOnModel(colmap, paths, paths.RawModel(), command, std::move(arguments), log_name, total, progress);
}

SparseModel AdjustRawModel(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                           const std::string& log_name, Progress& progress) {
  return RunOnRawModel(colmap, paths, "bundle_adjuster", options, log_name, 0, progress);
}

SparseModel AdjustModel(const Colmap& colmap, const Workspace& paths, const SparseModel& model,
                        const std::vector<std::string>& options, const std::string& log_name, Progress& progress) {
  const fs::path input = paths.PartialModelScratch();
  RemoveAll(input);
  WriteSparseModel(model, input, SparseFormat::kBinary);
  SparseModel adjusted = RunOnModel(colmap, paths, input, "bundle_adjuster", options, log_name, 0, progress);
  RemoveAll(input);
  return adjusted;
}

SparseModel RetriangulateRawModel(const Colmap& colmap, const Workspace& paths, const fs::path& image_dir,
                                  Progress& progress) {
  const fs::path input = paths.PartialModelScratch();
  RemoveAll(input);
  WriteSparseModel(CamerasAndPoses(ReadSparseModel(paths.RawModel())), input, SparseFormat::kBinary);
  std::vector<std::string> arguments = MapperInputs(paths, image_dir);
  Append(arguments, FixedIntrinsicsArguments());
  Append(arguments, {"--Mapper.tri_ignore_two_view_tracks", "0"});
  SparseModel model = RunOnModel(colmap, paths, input, "point_triangulator", arguments, "retriangulate", 0, progress);
  RemoveAll(input);
  return model;
}

SparseModel RegisterOtherPhotos(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                                int num_images, Progress& progress) {
  std::vector<std::string> arguments = {"--database_path", paths.Database().string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  return RunOnRawModel(colmap, paths, "image_registrator", arguments, "register", num_images, progress);
}

}  // namespace parallax

#include "colmap/raw_model.h"

#include <algorithm>
#include <map>
#include <utility>

#include "colmap/database.h"
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

}  // namespace

std::vector<std::string> FixedIntrinsicsArguments() {
  return {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
          "--Mapper.ba_refine_extra_params", "0"};
}

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

std::string NoInitialPairReason(const fs::path& database, int num_images) {
  const std::vector<VerifiedPair> pairs = ReadVerifiedPairs(database);
  if (pairs.empty()) {
    return "the photos share no features: no two of the " + std::to_string(num_images) +
           " photos have enough matching features to pass geometric verification (different "
           "scenes, too little texture or too little overlap)";
  }
  const bool no_parallax = std::all_of(pairs.begin(), pairs.end(), [](const VerifiedPair& pair) {
    return pair.geometry == PairGeometry::kPlanarOrPanoramic || pair.geometry == PairGeometry::kPanoramic;
  });
  if (!no_parallax) return "";
  const VerifiedPair& best = *std::max_element(
      pairs.begin(), pairs.end(), [](const VerifiedPair& a, const VerifiedPair& b) { return a.inliers < b.inliers; });
  return "the photos have no parallax: each of the " + std::to_string(pairs.size()) +
         " matched pairs is explained by a homography (the best, " + best.first + " and " + best.second +
         ", by " + std::to_string(best.inliers) + " matches), as for near-identical photos or photos "
         "taken from one spot; take the photos from positions a step or more apart";
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

SparseModel LargestModel(const std::vector<fs::path>& dirs) {
  SparseModel best;
  for (const fs::path& dir : dirs) {
    SparseModel model = ReadSparseModel(dir);
    if (model.Images().size() > best.Images().size()) best = std::move(model);
  }
  return best;
}

namespace {

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

SparseModel RegisterOtherPhotos(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                                int num_images, Progress& progress) {
  std::vector<std::string> arguments = {"--database_path", paths.Database().string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  return RunOnRawModel(colmap, paths, "image_registrator", arguments, "register", num_images, progress);
}

SparseModel AlignKnownModelToDatabase(const SparseModel& known, const std::vector<std::string>& names,
                                      const fs::path& known_dir, const fs::path& database) {
  const std::map<std::string, DatabaseImage> ids = ReadDatabaseImages(database);
  const bool single = known.Cameras().size() == 1;
  SparseModel aligned;
  for (const std::string& name : names) {
    const SparseImage* image = known.FindImageByName(name);
    if (!image) {
      throw BadInputError("--known-cameras " + known_dir.string() + " has no image named " + name);
    }
    const auto id = ids.find(name);
    if (id == ids.end()) {
      throw BadInputError(database.string() + " has no image named " + name);
    }
    SparseImage copy = *image;
    copy.id = id->second.image_id;
    copy.camera_id = id->second.camera_id;
    copy.points2d.clear();
    // One shared camera in the database when the known model has one (single_camera).
    if (!(single && !aligned.Cameras().empty())) {
      Camera camera = known.CameraById(image->camera_id);
      camera.id = copy.camera_id;
      aligned.AddCamera(camera);
    }
    aligned.AddImage(std::move(copy));
  }
  return aligned;
}

}  // namespace parallax

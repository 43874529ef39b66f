#include "eval/register_held_out.h"

#include <algorithm>
#include <array>
#include <map>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "colmap/runner.h"
#include "colmap/database.h"
#include "colmap/verification.h"
#include "sfm/pair_matching.h"
#include "sfm/photo_conversion.h"
#include "sfm/photo_set.h"
#include "sfm/quality_settings.h"

namespace parallax {
namespace fs = std::filesystem;

namespace {

// The names the held-out photos are registered under: each with a prefix that no image of the
// database starts with, so a held-out photo named like a training photo is still told apart.
std::map<std::string, std::string> StagedNames(const std::vector<std::string>& names,
                                               const std::map<std::string, DatabaseImage>& in_database) {
  std::string prefix = "held-out-";
  const auto taken = [&](const std::string& candidate) {
    return std::any_of(in_database.begin(), in_database.end(),
                       [&](const auto& image) { return image.first.starts_with(candidate); });
  };
  while (taken(prefix)) prefix += "x";
  std::map<std::string, std::string> staged;
  for (const std::string& name : names) staged[name] = prefix + fs::path(name).filename().string();
  return staged;
}

// The SIFT settings the workspace's photos were extracted with (report.json), so that the
// held-out photos' features are found at the same scale; a workspace whose report does not
// record them (made before it did, or from known cameras by hand) used balanced's.
QualitySettings WorkspaceFeatureSettings(const Workspace& ws) {
  QualitySettings settings = SettingsFor(Quality::kBalanced);
  if (!fs::exists(ws.Report())) return settings;
  try {
    const nlohmann::json report = nlohmann::json::parse(ReadFileBytes(ws.Report()));
    const nlohmann::json::json_pointer features("/reconstruct/features");
    if (!report.contains(features)) return settings;
    settings.max_image_size = report.at(features).at("max_image_size").get<int>();
    settings.max_num_features = report.at(features).at("max_num_features").get<int>();
  } catch (const nlohmann::json::exception& e) {
    throw BadInputError(ws.Report().string() + ": cannot read the feature settings: " + e.what());
  }
  if (settings.max_image_size <= 0 || settings.max_num_features <= 0) {
    throw BadInputError(ws.Report().string() + ": feature settings must be positive");
  }
  return settings;
}

// Links (or copies) each photo into <work_dir>/photos under its staged name; a photo colmap
// cannot read as it is (16-bit, grey, turned, ...) is converted there as `reconstruct` does.
void StagePhotos(const fs::path& images_dir, const std::map<std::string, std::string>& staged,
                 const fs::path& photos_dir) {
  fs::create_directories(photos_dir);
  for (const auto& [name, staged_name] : staged) {
    Photo photo;
    if (!CheckPhoto(images_dir / name, photo) && !photo.conversion.empty()) {
      WriteReadablePhoto(images_dir / name, photos_dir / staged_name);
      continue;
    }
    std::error_code error;
    fs::create_hard_link(images_dir / name, photos_dir / staged_name, error);
    if (error) fs::copy_file(images_dir / name, photos_dir / staged_name);
  }
}

// Copies the database into `work_dir`, adds the photos' features (under their staged names)
// (extracted with `features`, as the database's were) and their matches with every registered
// image, and registers them into a copy of `raw_model` at <work_dir>/model. Throws ToolError
// when colmap fails.
void RegisterWithColmap(const fs::path& database, const fs::path& raw_model, const SparseModel& model,
                        const QualitySettings& features, const fs::path& images_dir,
                        const std::map<std::string, std::string>& staged, const std::string& list,
                        const fs::path& work_dir, Progress& progress) {
  const fs::path registered = work_dir / "model";
  fs::remove_all(work_dir);
  fs::create_directories(registered);
  const fs::path photos_dir = work_dir / "photos";
  StagePhotos(images_dir, staged, photos_dir);
  const fs::path db = work_dir / "database.db";
  fs::copy_file(database, db);
  WriteFileAtomically(work_dir / "image_list.txt", list);
  const Colmap colmap;
  const fs::path log = work_dir / "colmap.log";
  const int count = static_cast<int>(staged.size());
  std::vector<std::string> extract = {
      "--database_path", db.string(), "--image_path", photos_dir.string(),
      "--image_list_path", (work_dir / "image_list.txt").string(),
      "--SiftExtraction.use_gpu", "0",
      "--SiftExtraction.max_image_size", std::to_string(features.max_image_size),
      "--SiftExtraction.max_num_features", std::to_string(features.max_num_features)};
  // One shared camera (the usual capture, or one camera per photo with the same intrinsics, as
  // calibrated datasets list them): the held-out photos are taken with it. Registering them
  // with a camera of their own instead would estimate its focal length, and trade it against
  // the pose.
  const Camera& first = model.Cameras().front();
  const bool one_camera = std::all_of(model.Cameras().begin(), model.Cameras().end(), [&](const Camera& camera) {
    return camera.model == first.model && camera.width == first.width && camera.height == first.height &&
           camera.params == first.params;
  });
  if (one_camera) {
    extract.insert(extract.end(), {"--ImageReader.existing_camera_id", std::to_string(first.id)});
  } else {
    extract.insert(extract.end(), {"--ImageReader.single_camera", "1"});
  }
  uint32_t last_id = 0;  // The held-out photos are numbered after it.
  for (const auto& [name, image] : ReadDatabaseImages(db)) last_id = std::max(last_id, image.image_id);
  colmap.Run("feature_extractor", extract, log, "held-out features", count, progress);
  NumberImagesByName(db, last_id);
  // Each held-out photo with every registered one, matched by brute force (colmap's matcher does
  // not repeat itself) and verified in fixed parts: the same on every run.
  const std::map<std::string, DatabaseImage> ids = ReadDatabaseImages(db);
  std::vector<std::array<uint32_t, 2>> pairs;
  for (const auto& [name, staged_name] : staged) {
    for (const SparseImage& image : model.Images()) {
      pairs.push_back({ids.at(staged_name).image_id, ids.at(image.name).image_id});
    }
  }
  MatchAndStorePairs(db, pairs);
  VerifyMatches(colmap, db, pairs, tbb::this_task_arena::max_concurrency(), {"--SiftMatching.use_gpu", "0"}, log,
                "held-out matches", progress);
  colmap.Run("image_registrator",
             {"--database_path", db.string(), "--input_path", raw_model.string(),
              "--output_path", registered.string()},
             log, "held-out registration", count, progress);
  fs::remove(db);  // A copy of the workspace's, plus a few images: not worth keeping.
  fs::remove_all(photos_dir);
}

}  // namespace

HeldOutRegistration RegisterHeldOutPhotos(const fs::path& workspace, const fs::path& images_dir,
                                          const std::vector<std::string>& names,
                                          const fs::path& work_dir, Progress& progress) {
  HeldOutRegistration result;
  const Workspace ws(workspace);
  const fs::path database = ws.Database();
  const fs::path raw_model = ws.RawModel();
  if (!fs::exists(database) || !DetectSparseFormat(raw_model)) {
    result.note = "no SfM database and model in " + ws.Sfm().string() +
                  " (made from known cameras?)";
    return result;
  }
  const SparseModel model = ReadSparseModel(raw_model);
  const QualitySettings features = WorkspaceFeatureSettings(ws);
  // Photos the database holds already (registered or not) would be taken for these.
  const std::map<std::string, DatabaseImage> in_database = ReadDatabaseImages(database);
  const std::map<std::string, std::string> staged = StagedNames(names, in_database);
  std::string list;
  Hasher key_hasher;
  key_hasher.Add("held-out-6")
      .Add(static_cast<uint64_t>(fs::file_size(database)))
      .Add(static_cast<uint64_t>(features.max_image_size))
      .Add(static_cast<uint64_t>(features.max_num_features));
  std::vector<fs::path> model_files(fs::directory_iterator(raw_model), fs::directory_iterator{});
  std::sort(model_files.begin(), model_files.end());
  for (const fs::path& file : model_files) key_hasher.Add(ReadFileBytes(file));
  for (const std::string& name : names) {
    const std::string& staged_name = staged.at(name);
    list += staged_name + "\n";
    key_hasher.Add(name).Add(ReadFileBytes(images_dir / name));
  }
  const std::string key = key_hasher.Hex();
  const fs::path registered = work_dir / "model";
  const fs::path key_file = work_dir / "key.txt";
  const bool reuse = fs::exists(key_file) && ReadFileBytes(key_file) == key &&
                     DetectSparseFormat(registered);
  if (!reuse) {
    try {
      RegisterWithColmap(database, raw_model, model, features, images_dir, staged, list, work_dir,
                         progress);
      WriteFileAtomically(key_file, key);
    } catch (const ToolError& e) {  // Only colmap's failure is a result; the rest is an error.
      result.note = std::string("colmap could not register them: ") + e.what();
      return result;
    }
  }
  const SparseModel with_held_out = ReadSparseModel(registered);
  for (const auto& [name, staged_name] : staged) {
    if (const SparseImage* image = with_held_out.FindImageByName(staged_name)) {
      result.registered[name] = {with_held_out.CameraById(image->camera_id), image->cam_from_world};
    }
  }
  result.note = std::to_string(result.registered.size()) + " of " +
                std::to_string(names.size()) +
                " registered into the SfM model by colmap image_registrator (SIFT at up to " +
                std::to_string(features.max_image_size) + " px, " + std::to_string(features.max_num_features) +
                " features, as the workspace's)" +
                (reuse ? " (reused from " + work_dir.string() + ")" : " (" + work_dir.string() + ")");
  return result;
}

}  // namespace parallax

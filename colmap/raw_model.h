#pragma once
// colmap's raw (distorted) models in a workspace: the command lines that map them from the
// database into Workspace::Models (one folder per model), the largest of them kept as
// Workspace::RawModel, and the colmap commands run on that model afterwards (bundle
// adjustment, registration of more photos). Each command runs through Colmap::Run, with its log
// in Workspace::Log.
#include <filesystem>
#include <string>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"
#include "core/sparse_model.h"
#include "core/workspace.h"

namespace parallax {

// The mapper options that hold every camera's intrinsics fixed in its bundle adjustments.
std::vector<std::string> FixedIntrinsicsArguments();

// colmap point_triangulator's arguments: the points of the known model
// (Workspace::KnownModel) triangulated from the database's matches into `output`, the
// intrinsics fixed. `image_dir`: the photos colmap reads.
std::vector<std::string> PointTriangulatorArguments(const Workspace& paths, const std::filesystem::path& image_dir,
                                                    const std::filesystem::path& output);

// colmap mapper's arguments: one incremental model of the photos listed in `image_list`, its
// models written under `output`.
std::vector<std::string> MapperArguments(const Workspace& paths, const std::filesystem::path& image_dir,
                                         const std::filesystem::path& output,
                                         const std::filesystem::path& image_list, bool fixed_intrinsics);

// colmap hierarchical_mapper's arguments: clusters of at most `cluster_images` photos mapped
// apart, overlapping by half of that, then merged; every photo of the database is mapped.
std::vector<std::string> HierarchicalMapperArguments(const Workspace& paths, const std::filesystem::path& image_dir,
                                                     const std::filesystem::path& output, int cluster_images,
                                                     bool fixed_intrinsics);

// Runs colmap `command` (a mapper) with `arguments`, its log and progress under `name`. Where it
// fails for want of a pair to start from and the database's matches say why
// (NoInitialPairReason), throws BadInputError naming the reason and the log; any other failure
// is colmap's ToolError.
void RunMapper(const Colmap& colmap, const Workspace& paths, const std::string& command,
               const std::vector<std::string>& arguments, const std::string& name, int num_images,
               Progress& progress);

// Why the mapper found no pair of photos to start from, where the verified matches in
// `database` show it: no pair at all, or only pairs one homography explains (photos from one
// spot, near-identical copies). "" when the matches do not explain it.
std::string NoInitialPairReason(const std::filesystem::path& database, int num_images);

// The model folders the mapper wrote in Workspace::Models, in name order. Throws BadInputError
// naming the mapper's log when there is none.
std::vector<std::filesystem::path> ModelDirs(const Workspace& paths);

// The model with the most registered images among `dirs` (the first of equals).
SparseModel LargestModel(const std::vector<std::filesystem::path>& dirs);

// The model colmap `command` writes from the raw model (`--input_path`) with `arguments`,
// through Workspace::RefinedModelScratch, which is removed afterwards. `total`: the units of
// work its progress lines count (0: none). The raw model itself is left as it was.
SparseModel RunOnRawModel(const Colmap& colmap, const Workspace& paths, const std::string& command,
                          std::vector<std::string> arguments, const std::string& log_name, int total,
                          Progress& progress);

// The raw model after one colmap bundle_adjuster run with `options` (the raw model is left as it
// was).
SparseModel AdjustRawModel(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                           const std::string& log_name, Progress& progress);

// `model` after one colmap bundle_adjuster run with `options`, through
// Workspace::PartialModelScratch (removed afterwards).
SparseModel AdjustModel(const Colmap& colmap, const Workspace& paths, const SparseModel& model,
                        const std::vector<std::string>& options, const std::string& log_name, Progress& progress);

// The raw model with every other photo the database can place registered to its points (colmap
// image_registrator with `options`: each photo's pose from its matches with the model's
// points; no points are added and the model is not adjusted). The raw model is left as it was.
SparseModel RegisterOtherPhotos(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                                int num_images, Progress& progress);

// The known model rewritten with the ids colmap's database gave the photos `names`, so that
// point_triangulator can match its images and cameras to the features and matches; without
// keypoints, and with one shared camera when the known model has one. Throws BadInputError when
// the known model (read from `known_dir`) or the database lacks one of the photos.
SparseModel AlignKnownModelToDatabase(const SparseModel& known, const std::vector<std::string>& names,
                                      const std::filesystem::path& known_dir,
                                      const std::filesystem::path& database);

}  // namespace parallax

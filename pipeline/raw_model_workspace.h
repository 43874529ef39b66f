#pragma once
// What colmap runs on a workspace's raw (distorted) models: the command lines that map them from
// the database into Workspace::Models (one folder per model), the largest of them kept as
// Workspace::RawModel, and the colmap commands run on that model afterwards (bundle adjustment,
// registration of more photos). Each command runs through Colmap::Run, with its log in
// Workspace::Log.
#include <filesystem>
#include <string>
#include <vector>

#include "colmap/runner.h"
#include "core/progress.h"
#include "core/sparse_model.h"
#include "core/workspace.h"

namespace parallax {

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

// The model folders the mapper wrote in Workspace::Models, in name order. Throws BadInputError
// naming the mapper's log when there is none.
std::vector<std::filesystem::path> ModelDirs(const Workspace& paths);

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

// The raw model's points triangulated afresh from the database's verified matches (colmap
// point_triangulator on its cameras and poses alone, which it holds as they are; tracks of two
// photos kept). `image_dir`: the photos colmap reads. The raw model is left as it was.
SparseModel RetriangulateRawModel(const Colmap& colmap, const Workspace& paths, const std::filesystem::path& image_dir,
                                  Progress& progress);

// The raw model with every other photo the database can place registered to its points (colmap
// image_registrator with `options`: each photo's pose from its matches with the model's
// points; no points are added and the model is not adjusted). The raw model is left as it was.
SparseModel RegisterOtherPhotos(const Colmap& colmap, const Workspace& paths, const std::vector<std::string>& options,
                                int num_images, Progress& progress);

}  // namespace parallax

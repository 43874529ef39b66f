#pragma once
// Internal to core/: what sparse_model.cc (the model and the folder-level read/write),
// sparse_model_binary.cc and sparse_model_text.cc (the two COLMAP formats) share. Not part of
// the library's interface; include core/sparse_model.h instead.
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/sparse_model.h"

namespace parallax::sparse_formats {

// Readers: append the entries of one file to `model`, checking each as it is read. Cameras
// must be read before images, which are checked against them. Throw BadInputError naming the
// file and the entry (binary) or line (text).
void ReadCamerasBinary(const std::filesystem::path& path, SparseModel* model);
void ReadImagesBinary(const std::filesystem::path& path, SparseModel* model);
void ReadPoints3DBinary(const std::filesystem::path& path, SparseModel* model);
void ReadCamerasText(const std::filesystem::path& path, SparseModel* model);
void ReadImagesText(const std::filesystem::path& path, SparseModel* model);
void ReadPoints3DText(const std::filesystem::path& path, SparseModel* model);

// Writers: the whole contents of one file. They do not check the model; callers run
// CheckWritable first.
std::string CamerasBinary(const SparseModel& model);
std::string ImagesBinary(const SparseModel& model);
std::string Points3DBinary(const SparseModel& model);
std::string CamerasText(const SparseModel& model);
std::string ImagesText(const SparseModel& model);
std::string Points3DText(const SparseModel& model);

// The number of 2D points with a 3D point (for the text headers' means).
uint64_t NumObservations(const SparseModel& model);

// Whether the text format can hold `name` as an image name.
bool IsTextSafeName(const std::string& name);

}  // namespace parallax::sparse_formats

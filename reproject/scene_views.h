#pragma once
// Source views from a scene folder's view set (images, COLMAP model, depth EXRs), through the
// core readers.
#include <string>
#include <vector>

#include "core/scene_folder.h"
#include "reproject/view.h"

namespace parallax {

// The cameras and poses of a view set, in the model's image order.
std::vector<PosedCamera> ReadPosedCameras(const ViewSetPaths& paths, std::vector<std::string>* names);

// Every image of the view set with its depth: color converted from the sRGB file to linear
// RGB (alpha dropped). Throws BadInputError naming the file for a missing or corrupt one,
// InternalError when an image, its depth and its camera disagree in size.
std::vector<SourceView> ReadSourceViews(const ViewSetPaths& paths);

}  // namespace parallax

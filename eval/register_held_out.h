#pragma once
// Poses of held-out photos (a scene's novel views) in a reconstruction's frame, the way
// novel-view benchmarks get them: COLMAP registers the photos into the finished SfM model.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/progress.h"
#include "reproject/view.h"

namespace parallax {

struct HeldOutRegistration {
  // By image name, the registered ones only: each pose with the camera it was solved with.
  std::map<std::string, PosedCamera> registered;
  std::string note;  // What was done (or reused), or why nothing was registered.
};

// Registers the photos `names` of `images_dir` into the SfM model of `workspace` (<ws>/sfm/sparse
// and its database): SIFT features with the workspace's shared camera, extracted at the scale and
// count its photos were (report.json's reconstruct.features; balanced's where the report predates
// them), matched against every registered training photo, then `colmap image_registrator`, which
// adds the photos without moving the training cameras (the depth maps stay valid). The photos'
// pixels give their poses only; nothing is rendered from them. Aligning ground-truth poses with a
// similarity instead carries the reconstruction's local pose errors into the novel cameras. Work
// and logs go to `work_dir`; a second call with the same photos (names and bytes), the same model
// and database size reuses the result. The photos are registered under prefixed names, so they may
// share names with training photos. Returns an empty map and the reason when the workspace has no
// database (e.g. made from known cameras) or COLMAP fails; throws BadInputError when report.json's
// record of the features is damaged, and lets every other error through. The registration solves
// each pose with the workspace's estimated camera, so a render puts the scene where the photo
// shows it with that camera and pose only: the ground-truth intrinsics with the same pose would
// shift it by their difference (2.2, 2.6 px of principal point on castle-p19).
HeldOutRegistration RegisterHeldOutPhotos(const std::filesystem::path& workspace,
                                          const std::filesystem::path& images_dir,
                                          const std::vector<std::string>& names,
                                          const std::filesystem::path& work_dir,
                                          Progress& progress);

}  // namespace parallax

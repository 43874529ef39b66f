// Matching through the real colmap on example_images/courtyard (24 photos 15 degrees apart on a
// ring; every other one is too sparse for SfM at fast quality): up to the exhaustive limit,
// parallax's brute force against colmap's own matcher; past it, sequential for photos in
// capture order, retrieval when their names are shuffled, both from a vocabulary tree built
// from the photos (built once, in the ordered run, and given to the shuffled one as
// --vocab-tree would).
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "colmap/database.h"
#include "colmap/runner.h"
#include "colmap/verification.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "core/workspace.h"
#include "eval/evaluate.h"
#include "pipeline/reconstruct.h"
#include "sfm/feature_matching.h"
#include "synth/scene.h"
#include "synth/synth.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;
const fs::path kCourtyard = SourceDir() / "example_images" / "courtyard";

// The courtyard's first `count` photos, the i-th under the name `name(i)`.
void CopyPhotos(const fs::path& folder, const std::function<std::string(int)>& name, int count = 24) {
  for (int i = 0; i < count; ++i) {
    char photo[16];
    std::snprintf(photo, sizeof(photo), "%04d.png", i);
    fs::copy_file(kCourtyard / "images" / photo, folder / name(i));
  }
}

// Past a limit of 10 images, with the next 3 and 8 retrieved images: fewer pairs than the 276
// of exhaustive matching.
ReconstructOptions MatchingPastTheLimit() {
  ReconstructOptions options;
  options.quality = Quality::kFast;
  options.estimate_depth = false;
  options.exhaustive_limit = 10;
  options.sequential_overlap = 4;
  options.retrieval_images = 8;
  return options;
}

const StageRecord& StageNamed(const ReconstructSummary& summary, const std::string& name) {
  for (const StageRecord& stage : summary.stages) {
    if (stage.name == name) return stage;
  }
  throw std::runtime_error("no stage " + name);
}

TEST(Matching, OrderedPhotosMatchSequentiallyShuffledOnesByRetrieval) {
  SilentProgress progress;
  const ReconstructOptions options = MatchingPastTheLimit();

  const TempDir ordered;
  const ReconstructSummary sequential = Reconstruct(kCourtyard / "images", ordered.Path(), options, progress);
  EXPECT_NE(sequential.matcher.find("sequential"), std::string::npos) << sequential.matcher;
  EXPECT_NE(sequential.matcher.find("100% of the photos consecutive in name order"),
            std::string::npos) << sequential.matcher;
  EXPECT_EQ(sequential.images_registered, 24);
  EXPECT_FALSE(StageNamed(sequential, "vocabulary tree").skipped);
  EXPECT_TRUE(fs::exists(Workspace(ordered.Path()).VocabularyTree()));
  const PoseEvaluation poses = EvaluatePoses(ReadSparseModel(ordered.Path() / "sparse"),
                                             ReadSparseModel(SceneFolder{kCourtyard}.Training().sparse));
  EXPECT_EQ(poses.registered, 24);
  EXPECT_LT(poses.rotation_error_mean_deg, 0.2);
  EXPECT_LT(ReadVerifiedPairs(Workspace(ordered.Path()).Database()).size(), 276u / 2);

  // Every 7th photo next: neighbours in name order are 105 degrees apart and share nothing.
  // The same photos' features: the ordered run's tree serves, and is not built again.
  const TempDir shuffled_photos, unordered;
  CopyPhotos(shuffled_photos.Path(), [](int i) { return "shuffled_" + std::to_string(10 + (i * 7) % 24) + ".png"; });
  ReconstructOptions given_tree = options;
  given_tree.vocab_tree = Workspace(ordered.Path()).VocabularyTree();
  const ReconstructSummary retrieval =
      Reconstruct(shuffled_photos.Path(), unordered.Path(), given_tree, progress);
  EXPECT_NE(retrieval.matcher.find("retrieval"), std::string::npos) << retrieval.matcher;
  EXPECT_NE(retrieval.matcher.find("not an ordered capture"), std::string::npos) << retrieval.matcher;
  EXPECT_NE(retrieval.matcher.find("the vocabulary tree " + given_tree.vocab_tree.string()), std::string::npos)
      << retrieval.matcher;
  const StageRecord& tree = StageNamed(retrieval, "vocabulary tree");
  EXPECT_TRUE(tree.skipped);
  EXPECT_NE(tree.reason.find(given_tree.vocab_tree.string()), std::string::npos) << tree.reason;
  EXPECT_FALSE(fs::exists(Workspace(unordered.Path()).VocabularyTree()));
  EXPECT_EQ(retrieval.images_registered, 24);
  EXPECT_LT(retrieval.mean_reprojection_error_px, 1.0);
  EXPECT_LT(ReadVerifiedPairs(Workspace(unordered.Path()).Database()).size(), 276u / 2);

  // A second run skips every stage, the vocabulary tree too, and still says which matcher ran.
  const ReconstructSummary again = Reconstruct(shuffled_photos.Path(), unordered.Path(), given_tree, progress);
  for (const StageRecord& stage : again.stages) EXPECT_TRUE(stage.skipped) << stage.name;
  EXPECT_EQ(again.matcher, retrieval.matcher);
}

TEST(Matching, AnAutomaticChoiceUpToTheLimitIsExhaustiveAndNeedsNoTree) {
  ReconstructOptions options;
  options.dry_run = true;
  SilentProgress progress;
  const TempDir workspace;
  const ReconstructSummary plan = Reconstruct(kCourtyard / "images", workspace.Path() / "ws", options, progress);
  EXPECT_NE(plan.matcher.find("exhaustive (24 images, every pair), chosen automatically"),
            std::string::npos) << plan.matcher;
  const StageRecord& tree = StageNamed(plan, "vocabulary tree");
  EXPECT_TRUE(tree.skipped);
  EXPECT_NE(tree.reason.find("exhaustive matching"), std::string::npos) << tree.reason;
}

// The courtyard's first six photos in `folder`/photos, their features extracted by colmap into
// `database` as fast quality does: the last three first, so that the images are numbered out of
// name order, as colmap's threads may number them (it numbers images in the order they finish).
void ExtractSixPhotos(const fs::path& folder, const fs::path& database) {
  const fs::path photos = folder / "photos", list = folder / "image_list.txt";
  fs::create_directories(photos);
  for (int i = 0; i < 6; ++i) {
    const std::string name = "000" + std::to_string(i) + ".png";
    fs::copy_file(kCourtyard / "images" / name, photos / name);
  }
  SilentProgress progress;
  for (const char* names : {"0003.png\n0004.png\n0005.png\n", "0000.png\n0001.png\n0002.png\n"}) {
    WriteFileAtomically(list, names);
    Colmap().Run("feature_extractor",
                 {"--database_path", database.string(), "--image_path", photos.string(), "--image_list_path",
                  list.string(), "--ImageReader.single_camera", "1", "--SiftExtraction.use_gpu", "0",
                  "--SiftExtraction.max_image_size", "1024", "--SiftExtraction.max_num_features", "2048"},
                 folder / "colmap.log", "features", 3, progress);
  }
}

// Each image's descriptors, by name.
std::map<std::string, std::vector<uint8_t>> DescriptorsByName(const fs::path& database) {
  std::map<uint32_t, std::string> names;
  for (const auto& [name, ids] : ReadDatabaseImages(database)) names[ids.image_id] = name;
  std::map<std::string, std::vector<uint8_t>> descriptors;
  for (DatabaseDescriptors& image : ReadDescriptors(database)) descriptors[names.at(image.image_id)] = image.data;
  return descriptors;
}

// Every pair of the database's images matched by brute force and stored; returns the pairs.
std::vector<std::array<uint32_t, 2>> MatchEveryPair(const fs::path& database) {
  const std::vector<DatabaseDescriptors> images = ReadDescriptors(database);
  std::vector<RawMatches> pairs;
  std::vector<std::array<uint32_t, 2>> ids;
  for (size_t i = 0; i < images.size(); ++i) {
    for (size_t j = i + 1; j < images.size(); ++j) {
      pairs.push_back({images[i].image_id, images[j].image_id,
                       MatchSiftFeatures({images[i].data.data(), images[i].rows},
                                         {images[j].data.data(), images[j].rows})});
      ids.push_back({images[i].image_id, images[j].image_id});
    }
  }
  WriteRawMatches(database, pairs);
  return ids;
}

// Each pair's matches and its verified inliers, by image ids.
struct PairCounts {
  std::map<std::pair<uint32_t, uint32_t>, std::set<std::array<uint32_t, 2>>> matches;
  std::map<std::pair<std::string, std::string>, int> inliers;
};

PairCounts ReadPairs(const fs::path& database) {
  PairCounts counts;
  for (const RawMatches& pair : ReadRawMatches(database)) {
    counts.matches[{pair.first_image_id, pair.second_image_id}].insert(pair.matches.begin(), pair.matches.end());
  }
  for (const VerifiedPair& pair : ReadVerifiedPairs(database)) counts.inliers[{pair.first, pair.second}] = pair.inliers;
  return counts;
}

// The brute-force matcher against colmap's own on the same features of six neighbouring
// courtyard photos at fast quality, each then verified by colmap. colmap's k-d trees find
// approximate neighbours by distance, the brute force the exact ones by dot product, and an
// approximate second neighbour passes the ratio test more easily: each keeps a few matches the
// other does not (~3%), and as many verify.
TEST(Matching, BruteForceKeepsWhatColmapsMatcherKeeps) {
  const TempDir folder;
  const fs::path theirs = folder.Path() / "colmap.db", ours = folder.Path() / "parallax.db";
  const fs::path log = folder.Path() / "colmap.log";
  ExtractSixPhotos(folder.Path(), theirs);
  fs::copy_file(theirs, ours);
  ASSERT_EQ(MatchEveryPair(ours).size(), 15u);
  const Colmap colmap;
  SilentProgress progress;
  for (const fs::path& database : {theirs, ours}) {
    colmap.Run("exhaustive_matcher", {"--database_path", database.string(), "--SiftMatching.use_gpu", "0"}, log,
               "matches", 6, progress);
  }

  const PairCounts colmap_pairs = ReadPairs(theirs), parallax_pairs = ReadPairs(ours);
  ASSERT_EQ(colmap_pairs.matches.size(), 15u);
  ASSERT_EQ(parallax_pairs.matches.size(), 15u);
  size_t colmap_total = 0, parallax_total = 0, common = 0;
  for (const auto& [pair, matches] : colmap_pairs.matches) {
    const std::set<std::array<uint32_t, 2>>& mine = parallax_pairs.matches.at(pair);
    colmap_total += matches.size();
    parallax_total += mine.size();
    for (const auto& match : matches) common += mine.count(match);
  }
  int colmap_inliers = 0, parallax_inliers = 0;
  for (const auto& [pair, inliers] : colmap_pairs.inliers) colmap_inliers += inliers;
  for (const auto& [pair, inliers] : parallax_pairs.inliers) parallax_inliers += inliers;
  std::printf("[ measure ] matches: colmap %zu, brute force %zu, common %zu; verified pairs %zu / %zu, "
              "inliers %d / %d\n",
              colmap_total, parallax_total, common, colmap_pairs.inliers.size(), parallax_pairs.inliers.size(),
              colmap_inliers, parallax_inliers);
  EXPECT_GT(colmap_total, 1000u);
  EXPECT_GE(common, colmap_total * 93 / 100);
  EXPECT_GE(common, parallax_total * 93 / 100);
  // 14 or 15 pairs verify, either way: the pair 75 degrees apart is on the edge (~15 inliers).
  EXPECT_GE(parallax_pairs.inliers.size() + 1, colmap_pairs.inliers.size());
  EXPECT_GE(parallax_inliers, colmap_inliers * 97 / 100);
}

// Numbered by name, each of the six photos keeps its descriptors. A database numbered already
// stays as it is; images with matches are refused, and photos added later are numbered after
// the others.
TEST(Database, ImagesAreNumberedByName) {
  const TempDir folder;
  const fs::path database = folder.Path() / "database.db";
  ExtractSixPhotos(folder.Path(), database);
  const auto before = DescriptorsByName(database);
  ASSERT_EQ(before.size(), 6u);
  EXPECT_GT(ReadDatabaseImages(database).at("0000.png").image_id, 3u);  // Numbered after the last three.

  NumberImagesByName(database);
  const std::map<std::string, DatabaseImage> images = ReadDatabaseImages(database);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(images.at("000" + std::to_string(i) + ".png").image_id, i + 1u);
  EXPECT_EQ(DescriptorsByName(database), before);
  EXPECT_EQ(ReadFeatureCounts(database).at("0003.png"), static_cast<int>(before.at("0003.png").size() / 128));

  NumberImagesByName(database);
  EXPECT_EQ(DescriptorsByName(database), before);
  MatchEveryPair(database);
  try {
    NumberImagesByName(database);
    FAIL() << "images with matches were numbered";
  } catch (const BadInputError& error) {
    EXPECT_NE(std::string(error.what()).find(database.string() + " by name: they have matches"), std::string::npos)
        << error.what();
  }

  // Photos added to the matched database (as evaluate registers held-out photos), read in the
  // reverse of name order.
  const fs::path list = folder.Path() / "more.txt";
  for (const char* name : {"0006.png", "0007.png"}) {
    fs::copy_file(kCourtyard / "images" / name, folder.Path() / "photos" / name);
  }
  WriteFileAtomically(list, "0007.png\n0006.png\n");
  SilentProgress progress;
  Colmap().Run("feature_extractor",
               {"--database_path", database.string(), "--image_path", (folder.Path() / "photos").string(),
                "--image_list_path", list.string(), "--SiftExtraction.use_gpu", "0",
                "--SiftExtraction.max_image_size", "1024", "--SiftExtraction.max_num_features", "2048"},
               folder.Path() / "colmap.log", "features", 2, progress);
  const auto added = DescriptorsByName(database);
  NumberImagesByName(database, 6);
  EXPECT_EQ(ReadDatabaseImages(database).at("0006.png").image_id, 7u);
  EXPECT_EQ(ReadDatabaseImages(database).at("0007.png").image_id, 8u);
  EXPECT_EQ(DescriptorsByName(database), added);
  EXPECT_THROW(NumberImagesByName(database, 5), BadInputError);
}

// The matches of the six photos verified twice in two parts, one colmap thread each: the same
// pairs with the same inliers both times, as many as colmap's own threads verify (whose random
// streams are shared among pairs in whatever order the threads take them); a few pairs verified
// alone; and no part's files left behind.
TEST(Matching, VerificationInPartsIsTheSameOnEveryRun) {
  const TempDir folder;
  const fs::path database = folder.Path() / "database.db";
  ExtractSixPhotos(folder.Path(), database);
  NumberImagesByName(database);
  const std::vector<std::array<uint32_t, 2>> pairs = MatchEveryPair(database);
  ASSERT_EQ(pairs.size(), 15u);
  const fs::path first = folder.Path() / "first.db", second = folder.Path() / "second.db",
                 threads = folder.Path() / "threads.db", log = folder.Path() / "verification.log";
  for (const fs::path& copy : {first, second, threads}) fs::copy_file(database, copy);
  const Colmap colmap;
  SilentProgress progress;
  const std::vector<std::string> options = {"--SiftMatching.use_gpu", "0"};
  for (const fs::path& copy : {first, second}) {
    VerifyMatches(colmap, copy, pairs, 2, options, log, "verification", progress);
  }
  colmap.Run("exhaustive_matcher", {"--database_path", threads.string(), "--SiftMatching.use_gpu", "0"}, log,
             "verification", 6, progress);

  const PairCounts once = ReadPairs(first), again = ReadPairs(second), threaded = ReadPairs(threads);
  EXPECT_EQ(once.inliers, again.inliers);
  int inliers = 0, threaded_inliers = 0;
  for (const auto& [pair, count] : once.inliers) inliers += count;
  for (const auto& [pair, count] : threaded.inliers) threaded_inliers += count;
  std::printf("[ measure ] verified pairs: in parts %zu, colmap's threads %zu; inliers %d / %d\n",
              once.inliers.size(), threaded.inliers.size(), inliers, threaded_inliers);
  EXPECT_GE(once.inliers.size(), 14u);
  EXPECT_LE(once.inliers.size(), threaded.inliers.size() + 1);
  EXPECT_GE(once.inliers.size() + 1, threaded.inliers.size());
  EXPECT_NEAR(inliers, threaded_inliers, threaded_inliers * 0.03);
  // Five pairs verified alone: only they gain a geometry, and every pair keeps its matches.
  const fs::path some = folder.Path() / "some.db";
  fs::copy_file(database, some);
  const std::vector<std::array<uint32_t, 2>> five(pairs.begin(), pairs.begin() + 5);
  VerifyMatches(colmap, some, five, 2, options, log, "verification", progress);
  const PairCounts some_pairs = ReadPairs(some);
  EXPECT_EQ(some_pairs.matches, ReadPairs(database).matches);
  EXPECT_GE(some_pairs.inliers.size(), 4u);
  EXPECT_LE(some_pairs.inliers.size(), 5u);
  const std::map<std::string, DatabaseImage> images = ReadDatabaseImages(database);
  for (const auto& [names, verified] : some_pairs.inliers) {
    const std::array<uint32_t, 2> ids = {images.at(names.first).image_id, images.at(names.second).image_id};
    EXPECT_NE(std::find(five.begin(), five.end(), ids), five.end()) << names.first << " " << names.second;
  }

  const std::string output = ReadFileBytes(log);
  size_t runs = 0;
  for (size_t at = 0; (at = output.find("exhaustive_matcher", at)) != std::string::npos; ++at) ++runs;
  EXPECT_EQ(runs, 7u);  // Two parts three times, and colmap's threads once.
  for (const auto& entry : fs::directory_iterator(folder.Path())) {
    EXPECT_EQ(entry.path().string().find(".part"), std::string::npos) << entry.path();
  }
}

// The same photos give the same cameras: structure from motion twice on the courtyard's first
// 12 photos at fast quality, its model the same bytes both times (the images numbered by name,
// the matches verified in fixed parts; colmap's mapper and adjustments repeat themselves given
// those).
TEST(Mapping, TheSamePhotosGiveTheSameCameras) {
  const TempDir photos, first, second;
  CopyPhotos(photos.Path(), [](int i) { return "photo_" + std::to_string(10 + i) + ".png"; }, 12);
  ReconstructOptions options;
  options.quality = Quality::kFast;
  options.estimate_depth = false;
  SilentProgress progress;
  const ReconstructSummary summary = Reconstruct(photos.Path(), first.Path(), options, progress);
  EXPECT_GE(summary.images_registered, 10);
  Reconstruct(photos.Path(), second.Path(), options, progress);
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string model = ReadFileBytes(first.Path() / "sparse" / file);
    EXPECT_FALSE(model.empty()) << file;
    EXPECT_TRUE(model == ReadFileBytes(second.Path() / "sparse" / file)) << file << " differs";
  }
}

// Tracks built afresh from the adjusted cameras, filtered and adjusted again, move the cameras
// of the small scene's 12 photos along an arc on: 0.150 -> 0.099 deg mean rotation error on 8
// December (docs/cameras.md, "Tracks built afresh"). The intrinsics stay as the adjustments
// before left them (freed, the focal length traded with the rotations: 0.20 deg).
TEST(Mapping, TracksBuiltAfreshMoveTheCamerasOn) {
  const fs::path small = SourceDir() / "example_images" / "small";
  ReconstructOptions options;
  options.estimate_depth = false;
  options.max_retriangulations = 0;
  SilentProgress progress;
  const TempDir kept, afresh;
  const ReconstructSummary without = Reconstruct(small / "images", kept.Path(), options, progress);
  options.max_retriangulations = ReconstructOptions().max_retriangulations;
  const ReconstructSummary with = Reconstruct(small / "images", afresh.Path(), options, progress);
  const auto rounds_note = [](const ReconstructSummary& summary) {
    for (const std::string& note : summary.notes) {
      if (note.starts_with("tracks built afresh")) return note;
    }
    return std::string();
  };
  EXPECT_EQ(rounds_note(without), "");
  EXPECT_NE(rounds_note(with).find(" px at most"), std::string::npos) << rounds_note(with);

  const SparseModel truth = ReadSparseModel(SceneFolder{small}.Training().sparse);
  const PoseEvaluation before = EvaluatePoses(ReadSparseModel(kept.Path() / "sparse"), truth);
  const PoseEvaluation after = EvaluatePoses(ReadSparseModel(afresh.Path() / "sparse"), truth);
  std::printf("[ measure ] mean rotation error: mapper's tracks %.4f deg, built afresh %.4f deg\n",
              before.rotation_error_mean_deg, after.rotation_error_mean_deg);
  EXPECT_EQ(after.registered, 12);
  EXPECT_LT(after.rotation_error_mean_deg, 0.8 * before.rotation_error_mean_deg);
  EXPECT_EQ(ReadSparseModel(Workspace(afresh.Path()).RawModel()).Cameras().front().params,
            ReadSparseModel(Workspace(kept.Path()).RawModel()).Cameras().front().params);
}

// Past a hierarchical limit of 10 images the 24 photos are mapped in clusters of at most 10,
// overlapping by 5, and merged into one model: every photo registered, the rotations a little
// worse than one incremental model's (as on the plaza at 400 views, docs/scale.md). (16 photos
// on an arc, not the ring, gave rotations 1.6 to 2 degrees off in 1 of 6 runs.)
TEST(Mapping, PastTheLimitClustersAreMappedApartAndMerged) {
  ReconstructOptions options;
  options.quality = Quality::kFast;
  options.estimate_depth = false;
  options.hierarchical_limit = 10;
  options.hierarchical_cluster_images = 10;
  SilentProgress progress;
  const TempDir workspace;
  const ReconstructSummary summary = Reconstruct(kCourtyard / "images", workspace.Path(), options, progress);
  EXPECT_NE(summary.mapper.find("hierarchical (clusters of at most 10 images mapped apart, then merged), "
                                "chosen automatically: 24 images, more than 10"),
            std::string::npos) << summary.mapper;
  const std::string log = ReadFileBytes(Workspace(workspace.Path()).Log("mapper"));
  EXPECT_NE(log.find("Partitioning scene"), std::string::npos);
  EXPECT_NE(log.find("Cluster 2 with"), std::string::npos);  // Two clusters or more.
  const PoseEvaluation poses = EvaluatePoses(ReadSparseModel(workspace.Path() / "sparse"),
                                             ReadSparseModel(SceneFolder{kCourtyard}.Training().sparse));
  EXPECT_EQ(poses.registered, 24);
  EXPECT_LT(poses.rotation_error_mean_deg, 0.5);
  std::printf("[ measure ] clusters merged: reprojection error %.3f px\n", summary.mean_reprojection_error_px);
  // Before the images were numbered by name and verified in fixed parts, runs differed: 1.12
  // and 1.23 px in 2 of 5 runs on 5 December (0.190 px in two runs since); a failed merge
  // leaves several pixels.
  EXPECT_LT(summary.mean_reprojection_error_px, 1.5);

  // Forced back to one incremental model, the mapper runs again (another key), and says so.
  options.mapper = MapperChoice::kIncremental;
  const ReconstructSummary incremental = Reconstruct(kCourtyard / "images", workspace.Path(), options, progress);
  EXPECT_EQ(incremental.mapper, "incremental (one model grown image by image)");
  EXPECT_FALSE(StageNamed(incremental, "mapper").skipped);
  EXPECT_TRUE(StageNamed(incremental, "matches").skipped);
  const PoseEvaluation one_model = EvaluatePoses(ReadSparseModel(workspace.Path() / "sparse"),
                                                 ReadSparseModel(SceneFolder{kCourtyard}.Training().sparse));
  std::printf("[ measure ] rotation error: hierarchical %.3f deg, incremental %.3f deg\n",
              poses.rotation_error_mean_deg, one_model.rotation_error_mean_deg);
  EXPECT_EQ(one_model.registered, 24);
  EXPECT_LT(one_model.rotation_error_mean_deg, 0.2);
}


// The courtyard from 72 cameras 5 degrees apart at 320x240: neighbours share about 43% of their
// features, photos two apart 25%.
void RenderDenseCourtyard(const fs::path& folder) {
  nlohmann::json scene = nlohmann::json::parse(ReadFileBytes(kCourtyard / "scene.json"));
  scene["image"] = {{"width", 320}, {"height", 240}, {"focal_px", 260}, {"supersampling", 1}};
  scene["cameras"]["training"][0]["count"] = 72;
  scene["cameras"]["novel"] = nlohmann::json::array();
  SilentProgress progress;
  RenderSceneFolder(ParseSceneJson(scene.dump(), "dense courtyard"), scene.dump(), folder, {}, progress);
}

// Key photos that share 20% of their features, every other photo: the mapper grows one model
// from them, the others are registered to it, and every photo ends up in the model with its
// true pose. Matched sequentially with the next 4 photos (fewer pairs than exhaustive).
TEST(Mapping, KeyPhotosAreMappedAndTheOthersRegisteredToThem) {
  const TempDir scene, workspace;
  RenderDenseCourtyard(scene.Path());
  ReconstructOptions options;
  options.quality = Quality::kFast;
  options.estimate_depth = false;
  options.matcher = MatcherChoice::kSequential;
  options.sequential_overlap = 5;
  options.mapper = MapperChoice::kKeyPhotos;
  options.key_photo_shared = 0.2;
  SilentProgress progress;
  const ReconstructSummary summary = Reconstruct(scene.Path() / "images", workspace.Path(), options, progress);
  std::printf("[ measure ] %s\n", summary.mapper.c_str());
  ASSERT_EQ(summary.mapper.rfind("key photos (one incremental model of ", 0), 0u) << summary.mapper;
  const std::string keys = ReadFileBytes(Workspace(workspace.Path()).KeyPhotoList());
  const auto key_count = std::count(keys.begin(), keys.end(), '\n');
  EXPECT_GE(key_count, 30);
  EXPECT_LE(key_count, 50);
  EXPECT_TRUE(fs::exists(Workspace(workspace.Path()).Log("register")));
  const PoseEvaluation poses = EvaluatePoses(ReadSparseModel(workspace.Path() / "sparse"),
                                             ReadSparseModel(SceneFolder{scene.Path()}.Training().sparse));
  std::printf("[ measure ] %d key photos; rotation error %.3f deg\n", static_cast<int>(key_count),
              poses.rotation_error_mean_deg);
  EXPECT_EQ(poses.registered, 72);
  EXPECT_LT(poses.rotation_error_mean_deg, 0.3);
  EXPECT_LT(summary.mean_reprojection_error_px, 1.0);

  // Run again, nothing runs; forced incremental, only the mapper would run again (a dry run
  // plans with the keys a run skips by: mapping all 72 photos adds nothing to check here).
  const ReconstructSummary again = Reconstruct(scene.Path() / "images", workspace.Path(), options, progress);
  for (const StageRecord& stage : again.stages) EXPECT_TRUE(stage.skipped) << stage.name;
  EXPECT_EQ(again.mapper, summary.mapper);
  options.mapper = MapperChoice::kIncremental;
  options.dry_run = true;
  const ReconstructSummary incremental = Reconstruct(scene.Path() / "images", workspace.Path(), options, progress);
  EXPECT_EQ(incremental.mapper, "incremental (one model grown image by image)");
  EXPECT_FALSE(StageNamed(incremental, "mapper").skipped);
  EXPECT_EQ(StageNamed(incremental, "mapper").reason, "inputs or options changed");
  EXPECT_TRUE(StageNamed(incremental, "matches").skipped);
}

}  // namespace
}  // namespace parallax

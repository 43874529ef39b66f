// The structure-from-motion decisions without colmap: where each automatic choice turns, and
// the camera setups --intrinsics and --known-cameras give.
#include "pipeline/sfm_policy.h"

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

Photo PhotoOfSize(const std::string& name, int width, int height) {
  Photo photo;
  photo.name = name;
  photo.width = width;
  photo.height = height;
  return photo;
}

PhotoSet PhotosOfOneSize() {
  return {{PhotoOfSize("a.png", 640, 480), PhotoOfSize("b.png", 640, 480)}, {}};
}

PhotoSet PhotosOfTwoSizes() {
  return {{PhotoOfSize("a.png", 640, 480), PhotoOfSize("b.png", 800, 600)}, {}};
}

std::vector<std::string> Names(int count) {
  std::vector<std::string> names;
  for (int i = 0; i < count; ++i) names.push_back("photo" + std::to_string(100 + i) + ".png");
  return names;
}

TEST(MatcherFor, TheAutomaticMatcherIsExhaustiveUpToTheLimitAndUndecidedPastIt) {
  ReconstructOptions options;
  options.exhaustive_limit = 75;
  EXPECT_EQ(MatcherFor(options, 75), MatcherChoice::kExhaustive);
  EXPECT_EQ(MatcherFor(options, 76), MatcherChoice::kAuto);
  EXPECT_EQ(PlannedMatcher(options, 76),
            "sequential or retrieval, as the photos' name order says once consecutive photos are matched "
            "(76 images, more than 75 for exhaustive matching)");
}

TEST(MatcherFor, TheUsersMatcherIsKeptOnAnyNumberOfPhotos) {
  ReconstructOptions options;
  options.matcher = MatcherChoice::kRetrieval;
  EXPECT_EQ(MatcherFor(options, 3), MatcherChoice::kRetrieval);
  options.matcher = MatcherChoice::kExhaustive;
  EXPECT_EQ(MatcherFor(options, 1000), MatcherChoice::kExhaustive);
  EXPECT_EQ(PlannedMatcher(options, 1000), "exhaustive (1000 images, every pair)");
}

TEST(MatcherForConsecutiveShare, AnOrderedCaptureFromTheOrderedShareOnIsMatchedSequentially) {
  ReconstructOptions options;
  options.ordered_share = 0.8;
  const std::vector<std::string> names = Names(6);
  // 4 of the 5 consecutive pairs verified (one in reverse order), plus one that is not consecutive.
  const std::vector<VerifiedPair> pairs = {{names[0], names[1]}, {names[2], names[1]}, {names[2], names[3]},
                                           {names[4], names[5]}, {names[0], names[5]}};
  const double share = ConsecutiveShare(names, pairs);
  EXPECT_DOUBLE_EQ(share, 0.8);
  EXPECT_EQ(MatcherForConsecutiveShare(options, share), MatcherChoice::kSequential);
  EXPECT_EQ(MatcherForConsecutiveShare(options, 0.6), MatcherChoice::kRetrieval);
  EXPECT_EQ(ConsecutiveShare({names[0]}, pairs), 0);
  EXPECT_EQ(DescribeMatcher(MatcherChoice::kRetrieval, options, 100, 0.6),
            "retrieval (each image with its 40 most similar in a vocabulary tree built from these photos), "
            "chosen automatically: 100 images, more than 75 for exhaustive matching, and 60% of the photos "
            "consecutive in name order match the next (not an ordered capture)");
  EXPECT_THROW(DescribeMatcher(MatcherChoice::kAuto, options, 100, 0.6), InternalError);
}

TEST(PlanByCount, TheAutomaticMapperTurnsHierarchicalPastTheLimitOnly) {
  ReconstructOptions options;
  options.hierarchical_limit = 800;
  const MapperPlan at_limit = PlanByCount(options, 800);
  EXPECT_EQ(at_limit.mapper, MapperChoice::kIncremental);
  EXPECT_EQ(at_limit.description,
            "incremental (one model grown image by image), chosen automatically: at most 800 images");
  const MapperPlan past_limit = PlanByCount(options, 801);
  EXPECT_EQ(past_limit.mapper, MapperChoice::kHierarchical);
  EXPECT_EQ(past_limit.description,
            "hierarchical (clusters of at most 100 images mapped apart, then merged), chosen automatically: "
            "801 images, more than 800 for one incremental model");
  options.mapper = MapperChoice::kIncremental;
  EXPECT_EQ(PlanByCount(options, 5000).description, "incremental (one model grown image by image)");
}

TEST(PlanKeyPhotos, KeyPhotosAreMappedOnlyWhereSomePhotosAreNotKeys) {
  ReconstructOptions options;
  EXPECT_FALSE(MayUseKeyPhotos(options, options.exhaustive_limit));
  EXPECT_TRUE(MayUseKeyPhotos(options, options.exhaustive_limit + 1));
  const std::vector<std::string> names = Names(100);
  EXPECT_EQ(PlanKeyPhotos(options, 100, std::nullopt).mapper, MapperChoice::kKeyPhotos);
  const MapperPlan every_photo = PlanKeyPhotos(options, 100, names);
  EXPECT_EQ(every_photo.mapper, MapperChoice::kIncremental);
  EXPECT_TRUE(every_photo.key_photos.empty());
  const MapperPlan some = PlanKeyPhotos(options, 100, std::vector<std::string>{names[0], names[50], names[99]});
  EXPECT_EQ(some.mapper, MapperChoice::kKeyPhotos);
  EXPECT_EQ(some.key_photos, (std::vector<std::string>{names[0], names[50], names[99]}));
  EXPECT_NE(some.description.find("one incremental model of 3 key photos"), std::string::npos) << some.description;
  EXPECT_NE(some.description.find("the other 97 registered to it"), std::string::npos) << some.description;
}

TEST(ChooseCameraSetup, OneFocalLengthOnPhotosOfDifferentSizesIsBadInput) {
  ReconstructOptions options;
  options.intrinsics = {1000};
  EXPECT_THROW(ChooseCameraSetup(PhotosOfTwoSizes(), options, nullptr), BadInputError);
  // Four intrinsics give the principal point, so the sizes may differ.
  options.intrinsics = {1000, 1001, 320.5, 240};
  const CameraSetup pinhole = ChooseCameraSetup(PhotosOfTwoSizes(), options, nullptr);
  EXPECT_EQ(pinhole.model, CameraModel::kPinhole);
  EXPECT_EQ(pinhole.params, "1000,1001,320.5,240");
  EXPECT_EQ(pinhole.sharing, CameraSharing::kAll);
  EXPECT_TRUE(pinhole.fixed_intrinsics);
}

TEST(ChooseCameraSetup, OneFocalLengthPutsThePrincipalPointAtTheImageCentre) {
  ReconstructOptions options;
  options.intrinsics = {1234.5};
  const CameraSetup setup = ChooseCameraSetup(PhotosOfOneSize(), options, nullptr);
  EXPECT_EQ(setup.model, CameraModel::kSimplePinhole);
  EXPECT_EQ(setup.params, "1234.5,320,240");
  EXPECT_EQ(DescribeCameraSetup(setup, PhotosOfOneSize()), "SIMPLE_PINHOLE, one shared camera, intrinsics fixed");
}

TEST(ChooseCameraSetup, EstimatedIntrinsicsGetOneCameraPerPhotoSize) {
  const ReconstructOptions options;
  const CameraSetup one = ChooseCameraSetup(PhotosOfOneSize(), options, nullptr);
  EXPECT_EQ(one.sharing, CameraSharing::kAll);
  EXPECT_FALSE(one.fixed_intrinsics);
  EXPECT_TRUE(one.params.empty());
  const CameraSetup two = ChooseCameraSetup(PhotosOfTwoSizes(), options, nullptr);
  EXPECT_EQ(two.sharing, CameraSharing::kPerGroup);
  EXPECT_EQ(DescribeCameraSetup(two, PhotosOfTwoSizes()),
            "SIMPLE_RADIAL, one camera per photo size and EXIF camera (2 cameras)");
}

TEST(ChooseCameraSetup, KnownCamerasAreFixedAndSharedOnlyWhereTheModelHasOneCamera) {
  const ReconstructOptions options;
  Camera camera;
  camera.id = 7;
  camera.model = CameraModel::kPinhole;
  camera.width = 640;
  camera.height = 480;
  camera.params = {500, 501.25, 320, 240};
  SparseModel known;
  known.AddCamera(camera);
  const CameraSetup one = ChooseCameraSetup(PhotosOfTwoSizes(), options, &known);
  EXPECT_EQ(one.model, CameraModel::kPinhole);
  EXPECT_EQ(one.params, "500,501.25,320,240");
  EXPECT_EQ(one.sharing, CameraSharing::kAll);
  EXPECT_TRUE(one.fixed_intrinsics);
  camera.id = 8;
  known.AddCamera(camera);
  const CameraSetup each = ChooseCameraSetup(PhotosOfOneSize(), options, &known);
  EXPECT_EQ(each.model, options.camera_model);
  EXPECT_TRUE(each.params.empty());
  EXPECT_EQ(each.sharing, CameraSharing::kPerPhoto);
  EXPECT_TRUE(each.fixed_intrinsics);
}

TEST(ExtractionRuns, PhotosAloneInTheirGroupShareOneRunWithoutSharingACamera) {
  const PhotoSet photos{{PhotoOfSize("a.png", 640, 480), PhotoOfSize("b.png", 800, 600),
                         PhotoOfSize("c.png", 640, 480), PhotoOfSize("d.png", 1024, 768)},
                        {}};
  const std::vector<ExtractionRun> runs = ExtractionRuns(photos, CameraSharing::kPerGroup);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].names, (std::vector<std::string>{"a.png", "c.png"}));
  EXPECT_TRUE(runs[0].single_camera);
  EXPECT_EQ(runs[1].names, (std::vector<std::string>{"b.png", "d.png"}));
  EXPECT_FALSE(runs[1].single_camera);
  const std::vector<ExtractionRun> one = ExtractionRuns(photos, CameraSharing::kPerPhoto);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].names.size(), 4u);
  EXPECT_FALSE(one[0].single_camera);
}

TEST(VocabularyTreeWords, HalfTheSampledDescriptorsBetweenOneAndTheTreesSize) {
  // 10 photos, all sampled: half of their 20,000 descriptors.
  EXPECT_EQ(VocabularyTreeWords(10, 20000), 10000);
  // 300 photos, 30 of them sampled: a tenth of the descriptors, halved.
  EXPECT_EQ(VocabularyTreeWords(300, 200000), 10000);
  EXPECT_EQ(VocabularyTreeWords(300, 100000000), kVocabularyTreeWords);
  EXPECT_EQ(VocabularyTreeWords(2, 1), 1);
}

TEST(RefinesPrincipalPoint, OnlyOneSharedEstimatedCameraFromTheMinimumPhotoCount) {
  ReconstructOptions options;
  options.refine_principal_point_min_images = 5;
  const CameraSetup shared{CameraModel::kSimpleRadial, "", CameraSharing::kAll, false};
  EXPECT_TRUE(RefinesPrincipalPoint(shared, options, 5));
  EXPECT_FALSE(RefinesPrincipalPoint(shared, options, 4));
  EXPECT_FALSE(RefinesPrincipalPoint({CameraModel::kSimpleRadial, "", CameraSharing::kPerGroup, false}, options, 50));
  EXPECT_FALSE(RefinesPrincipalPoint({CameraModel::kSimplePinhole, "500,320,240", CameraSharing::kAll, true}, options,
                                     50));
}

TEST(HeldOutPhotos, EveryNthFromTheFirstAndTheNamedOnes) {
  const std::vector<std::string> names = {"a", "b", "c", "d", "e", "f", "g", "h", "i"};
  EXPECT_EQ(HeldOutPhotos(names, 0, {}), std::set<std::string>());
  EXPECT_EQ(HeldOutPhotos(names, 4, {}), std::set<std::string>({"a", "e", "i"}));
  EXPECT_EQ(HeldOutPhotos(names, 8, {"c"}), std::set<std::string>({"a", "c", "i"}));
  EXPECT_THROW(HeldOutPhotos(names, 0, {"z"}), BadInputError);
  EXPECT_EQ(HeldOutPhotos(names, 0, {"a", "b", "c", "d", "e", "f", "g"}).size(), 7u);  // Two are left.
  EXPECT_THROW(HeldOutPhotos(names, 0, {"a", "b", "c", "d", "e", "f", "g", "h"}), BadInputError);
}

// A model of one 1000x500 camera whose principal point is at (x, y).
SparseModel OneCameraAt(double x, double y) {
  Camera camera;
  camera.id = 1;
  camera.model = CameraModel::kSimpleRadial;
  camera.width = 1000;
  camera.height = 500;
  camera.params = {800, x, y, 0};
  SparseModel model;
  model.AddCamera(camera);
  return model;
}

TEST(PhotoFolds, EveryKthPhotoByName) {
  SparseModel model;
  for (uint32_t i = 0; i < 5; ++i) {
    SparseImage image;
    image.id = i + 1;
    image.name = std::string(1, static_cast<char>('e' - i));
    model.AddImage(image);
  }
  using Folds = std::vector<std::vector<std::string>>;
  EXPECT_EQ(PhotoFolds(model, 2), Folds({{"a", "c", "e"}, {"b", "d"}}));
  EXPECT_EQ(PhotoFolds(model, 8), Folds({{"a"}, {"b"}, {"c"}, {"d"}, {"e"}}));
}

// Four folds predicting the left-out photos' 100 observations each at `freed_px` with the
// point freed against `centre_px` at the centre.
std::vector<FoldPrediction> FoldsAt(double centre_px, double freed_px) {
  return std::vector<FoldPrediction>(4, {{centre_px, 100}, {freed_px, 100}});
}

TEST(CheckRefinedPrincipalPoint, APointThatPredictsTheLeftOutPhotosIsKept) {
  const ReconstructOptions options;
  const PrincipalPointCheck kept = CheckRefinedPrincipalPoint(OneCameraAt(540, 250), FoldsAt(0.5, 0.45), 4.9, options);
  EXPECT_TRUE(kept.keep);
  EXPECT_EQ(kept.note,
            "principal point refined in a final bundle adjustment: the refined one is 4.0% off-centre, 8.2 standard "
            "deviations (4.9 px by the jackknife over 4 folds of the photos), and predicts the photos left out of it "
            "at 0.450 px against 0.500 px from the centre (better in 4 of the folds)");
  // Either side of the 0.3% gain the option asks for, 2 deviations off-centre: kept, then not.
  EXPECT_TRUE(CheckRefinedPrincipalPoint(OneCameraAt(540, 250), FoldsAt(0.5, 0.4984), 20, options).keep);
  EXPECT_FALSE(CheckRefinedPrincipalPoint(OneCameraAt(540, 250), FoldsAt(0.5, 0.4986), 20, options).keep);
}

// As on photos undistorted to a centred pinhole along a narrow arc: 2.9% off, but uncertain
// over the folds and no better at predicting the photos it was not adjusted on.
TEST(CheckRefinedPrincipalPoint, APointThatPredictsNoBetterStaysAtTheCentre) {
  const ReconstructOptions options;
  const PrincipalPointCheck rejected =
      CheckRefinedPrincipalPoint(OneCameraAt(529, 250), FoldsAt(0.5, 0.4995), 24.5, options);
  EXPECT_FALSE(rejected.keep);
  EXPECT_EQ(rejected.note,
            "principal point kept at the image centre: the refined one is 2.9% off-centre, 1.2 standard deviations "
            "(24.5 px by the jackknife over 4 folds of the photos), and predicts the photos left out of it at "
            "0.499 px against 0.500 px from the centre (better in 4 of the folds)");
  // Three deviations off the centre, a smaller gain suffices; none does not.
  EXPECT_TRUE(CheckRefinedPrincipalPoint(OneCameraAt(529, 250), FoldsAt(0.5, 0.4995), 9.6, options).keep);
  EXPECT_FALSE(CheckRefinedPrincipalPoint(OneCameraAt(529, 250), FoldsAt(0.5, 0.4995), 9.7, options).keep);
  EXPECT_FALSE(CheckRefinedPrincipalPoint(OneCameraAt(529, 250), FoldsAt(0.5, 0.5005), 1.2, options).keep);
  EXPECT_THROW(CheckRefinedPrincipalPoint(OneCameraAt(529, 250), {{{0.5, 100}, {0.4, 100}}}, 1, options),
               InternalError);
}

TEST(CheckRefinedPrincipalPoint, APointDriftedPastTheLimitStaysAtTheCentre) {
  ReconstructOptions options;
  options.max_refined_principal_point_offset = 0.05;
  const SparseModel drifted = OneCameraAt(500, 290);  // 8% of the height off-centre.
  EXPECT_TRUE(PrincipalPointDrifted(drifted, options));
  EXPECT_FALSE(PrincipalPointDrifted(OneCameraAt(520, 260), options));  // 2% off-centre.
  // The folds are not adjusted with the point freed: there are none to look at.
  const PrincipalPointCheck rejected = CheckRefinedPrincipalPoint(drifted, {}, 0, options);
  EXPECT_FALSE(rejected.keep);
  EXPECT_EQ(rejected.note,
            "principal point kept at the image centre: the refined one drifted 8.0% of the image size off-centre "
            "(not observable in these photos)");
}

}  // namespace
}  // namespace parallax

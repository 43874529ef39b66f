# Tests over ~30 s get the `slow` label besides their module's, for `ctest -LE slow`.
set_tests_properties(${bench_test_TESTS} PROPERTIES LABELS "bench;slow")
set_tests_properties(ReconstructCli.PhotosInEveryFormACameraWritesAreReconstructed PROPERTIES LABELS "cli;slow")
set_tests_properties(ReconstructCli.PhotosOfTwoSizesGetOneCameraPerSize PROPERTIES LABELS "cli;slow")
set_tests_properties(Slurm.JobArraysOnARealClusterWriteWhatALocalRunWrites PROPERTIES LABELS "cli;slow")
set_tests_properties(Matching.OrderedPhotosMatchSequentiallyShuffledOnesByRetrieval PROPERTIES LABELS "pipeline;slow")
set_tests_properties(Mapping.PastTheLimitClustersAreMappedApartAndMerged PROPERTIES LABELS "pipeline;slow")
set_tests_properties(Mapping.KeyPhotosAreMappedAndTheOthersRegisteredToThem PROPERTIES LABELS "pipeline;slow")

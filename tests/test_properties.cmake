# Properties of discovered tests, read after discovery (TEST_INCLUDE_FILES).

# Tests over ~30 s get the `slow` label besides their module's, for `ctest -LE slow`, and a
# cost (seconds, roughly) so that a parallel run starts them first.
set_tests_properties(${bench_test_TESTS} PROPERTIES LABELS "bench;slow" COST 100)
set_tests_properties(ReconstructCli.PhotosInEveryFormACameraWritesAreReconstructed PROPERTIES LABELS "cli;slow" COST 150)
set_tests_properties(ReconstructCli.PhotosOfTwoSizesGetOneCameraPerSize PROPERTIES LABELS "cli;slow" COST 150)
set_tests_properties(Slurm.JobArraysOnARealClusterWriteWhatALocalRunWrites PROPERTIES LABELS "cli;slow" COST 200)
set_tests_properties(Matching.OrderedPhotosMatchSequentiallyShuffledOnesByRetrieval PROPERTIES LABELS "pipeline;slow" COST 300)
set_tests_properties(Mapping.PastTheLimitClustersAreMappedApartAndMerged PROPERTIES LABELS "pipeline;slow" COST 200)
set_tests_properties(Mapping.KeyPhotosAreMappedAndTheOthersRegisteredToThem PROPERTIES LABELS "pipeline;slow" COST 300)

# scripts/test runs two tests at a time. Those sharing something that exists once per machine
# take turns: the one-node Slurm cluster (its daemons' ports and munge socket) and the first
# free X display number.
foreach(test IN LISTS cli_test_TESTS)
  if(test MATCHES "^Slurm\\.")
    set_tests_properties(${test} PROPERTIES RESOURCE_LOCK slurm)
  endif()
endforeach()
foreach(test IN LISTS viewer_test_TESTS)
  if(test MATCHES "^ViewWindow\\.")
    set_tests_properties(${test} PROPERTIES RESOURCE_LOCK x_display)
  endif()
endforeach()

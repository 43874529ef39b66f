# parallax_cpu_level: the instruction set of the render core (reproject/) and of multi-view
# stereo (mvs/), which link it. x86-64-v3 (AVX2, FMA, BMI2: every x86-64 CPU since about 2015)
# runs the render core ~15% faster than baseline x86-64 (K=4 render at 640x480 16.1 -> 13.6
# ms, bench/reproject_benchmark on a 2-core AMD EPYC), and PatchMatch's window cost takes eight
# samples at a time (mvs/patch_match.cc). AUTO uses it when the machine that builds parallax
# has it, so a build runs where it is made; OFF builds for any x86-64 CPU (to copy the binaries
# to an older machine); ON forces it. The rest of parallax stays baseline: `parallax synth`
# reproduces the committed example scenes byte for byte only without fused multiply-adds.
set(PARALLAX_X86_64_V3 AUTO CACHE STRING
    "Compile the render core and stereo for x86-64-v3: AUTO (when this machine has it), ON or OFF")
set_property(CACHE PARALLAX_X86_64_V3 PROPERTY STRINGS AUTO ON OFF)

include(CheckCXXCompilerFlag)
check_cxx_compiler_flag(-march=x86-64-v3 PARALLAX_COMPILER_HAS_X86_64_V3)
set(parallax_use_v3 OFF)
if(PARALLAX_X86_64_V3 STREQUAL "ON")
  set(parallax_use_v3 ON)
elseif(PARALLAX_X86_64_V3 STREQUAL "AUTO" AND PARALLAX_COMPILER_HAS_X86_64_V3
       AND NOT CMAKE_CROSSCOMPILING)
  try_run(parallax_v3_run parallax_v3_compiled ${CMAKE_BINARY_DIR}/cpu_level
          ${CMAKE_CURRENT_LIST_DIR}/has_x86_64_v3.cc)
  if(parallax_v3_compiled AND parallax_v3_run EQUAL 0)
    set(parallax_use_v3 ON)
  endif()
elseif(NOT PARALLAX_X86_64_V3 MATCHES "^(AUTO|ON|OFF)$")
  message(FATAL_ERROR "PARALLAX_X86_64_V3 is '${PARALLAX_X86_64_V3}': expected AUTO, ON or OFF")
endif()

add_library(parallax_cpu_level INTERFACE)
if(parallax_use_v3)
  target_compile_options(parallax_cpu_level INTERFACE -march=x86-64-v3)
  # With AVX, Eigen aligns fixed-size objects (quaternions, 4-vectors) to 32 bytes; kept at 16
  # so that they have one layout in the render core and in the code and libraries built for
  # baseline x86-64 that hand them over.
  target_compile_definitions(parallax_cpu_level INTERFACE EIGEN_MAX_STATIC_ALIGN_BYTES=16)
endif()
message(STATUS "parallax: render core and stereo compiled for x86-64-v3: ${parallax_use_v3} "
               "(PARALLAX_X86_64_V3=${PARALLAX_X86_64_V3})")

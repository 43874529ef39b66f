# The OpenCV modules parallax uses, as imported targets opencv_<module>.
# OpenCV's own CMake package comes only with Debian's libopencv-dev, which installs every module
# and what they pull (VTK, Open MPI, Tesseract: 43 packages, 330 MB unpacked). The modules'
# own -dev packages (libopencv-core-dev, ...) hold their headers and libraries but no CMake
# package, so they are found here.
set(parallax_opencv_modules core imgproc imgcodecs calib3d photo video)

find_path(PARALLAX_OPENCV_INCLUDE_DIR opencv2/core/version.hpp PATH_SUFFIXES opencv4
          DOC "OpenCV 4 headers (Debian package libopencv-core-dev)" REQUIRED)
file(STRINGS ${PARALLAX_OPENCV_INCLUDE_DIR}/opencv2/core/version.hpp parallax_opencv_version_lines
     REGEX "^#define CV_VERSION_(MAJOR|MINOR) ")
string(REGEX REPLACE ".*MAJOR +([0-9]+).*MINOR +([0-9]+).*" "\\1.\\2" parallax_opencv_version
       "${parallax_opencv_version_lines}")
if(parallax_opencv_version VERSION_LESS 4.6)
  message(FATAL_ERROR "OpenCV ${parallax_opencv_version} found in ${PARALLAX_OPENCV_INCLUDE_DIR}: "
                      "parallax needs 4.6 or newer (scripts/install-deps)")
endif()

# Each module links the modules it is built on, as OpenCV's own targets do: imgproc links
# core, the others imgproc (and so core).
foreach(module IN LISTS parallax_opencv_modules)
  find_library(PARALLAX_OPENCV_${module}_LIBRARY opencv_${module}
               DOC "OpenCV's ${module} module (Debian package libopencv-${module}-dev)" REQUIRED)
  add_library(opencv_${module} SHARED IMPORTED)
  set_target_properties(opencv_${module} PROPERTIES
    IMPORTED_LOCATION ${PARALLAX_OPENCV_${module}_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${PARALLAX_OPENCV_INCLUDE_DIR})
  if(module STREQUAL "imgproc")
    set_target_properties(opencv_${module} PROPERTIES INTERFACE_LINK_LIBRARIES opencv_core)
  elseif(NOT module STREQUAL "core")
    set_target_properties(opencv_${module} PROPERTIES INTERFACE_LINK_LIBRARIES opencv_imgproc)
  endif()
endforeach()
message(STATUS "OpenCV ${parallax_opencv_version}: ${parallax_opencv_modules}")

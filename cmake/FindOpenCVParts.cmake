# Finds the OpenCV modules blurcue uses from Debian's per-module -dev packages
# (libopencv-core-dev, -imgproc-dev, -imgcodecs-dev, -calib3d-dev, -videoio-dev), which ship no
# OpenCVConfig.cmake of their own (only the heavy libopencv-dev meta package does).
# Defines the imported targets OpenCV::parts (what blurcue links: core, imgproc, calib3d and what calib3d needs) and
# OpenCV::media (core, imgcodecs, videoio: only src/media's plugin links them, see core/media.h).
find_path(OpenCVParts_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_ocv_libs)
set(_ocv_missing)
foreach(m core imgproc imgcodecs calib3d videoio features2d flann)
  find_library(OpenCVParts_${m}_LIBRARY NAMES opencv_${m})
  if(OpenCVParts_${m}_LIBRARY)
    list(APPEND _ocv_libs ${OpenCVParts_${m}_LIBRARY})
  else()
    list(APPEND _ocv_missing ${m})
  endif()
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVParts REQUIRED_VARS OpenCVParts_INCLUDE_DIR OpenCVParts_core_LIBRARY
  OpenCVParts_imgproc_LIBRARY OpenCVParts_imgcodecs_LIBRARY OpenCVParts_calib3d_LIBRARY OpenCVParts_videoio_LIBRARY)
if(OpenCVParts_FOUND AND NOT TARGET OpenCV::parts)
  set(_ocv_media ${OpenCVParts_core_LIBRARY} ${OpenCVParts_imgcodecs_LIBRARY} ${OpenCVParts_videoio_LIBRARY})
  list(REMOVE_ITEM _ocv_libs ${OpenCVParts_imgcodecs_LIBRARY} ${OpenCVParts_videoio_LIBRARY})
  add_library(OpenCV::parts INTERFACE IMPORTED)
  set_target_properties(OpenCV::parts PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${OpenCVParts_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${_ocv_libs}")
  add_library(OpenCV::media INTERFACE IMPORTED)
  set_target_properties(OpenCV::media PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${OpenCVParts_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${_ocv_media}")
endif()

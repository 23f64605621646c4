# Finds the OpenCV modules relight uses from Debian's per-module -dev packages
# (libopencv-core-dev, libopencv-imgproc-dev, ...). OpenCV's own CMake config ships only in the
# libopencv-dev metapackage, which pulls ~130 further packages (VTK, Qt, ...) that relight does
# not need, so the modules are located directly. Creates imported targets OpenCV::<module>.
find_path(OpenCVModules_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_relight_opencv_libs)
foreach(module IN LISTS OpenCVModules_FIND_COMPONENTS)
  find_library(OpenCVModules_${module}_LIBRARY NAMES opencv_${module})
  list(APPEND _relight_opencv_libs OpenCVModules_${module}_LIBRARY)
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenCVModules REQUIRED_VARS OpenCVModules_INCLUDE_DIR ${_relight_opencv_libs})

if(OpenCVModules_FOUND)
  foreach(module IN LISTS OpenCVModules_FIND_COMPONENTS)
    if(NOT TARGET OpenCV::${module})
      add_library(OpenCV::${module} UNKNOWN IMPORTED)
      set_target_properties(OpenCV::${module} PROPERTIES
        IMPORTED_LOCATION "${OpenCVModules_${module}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${OpenCVModules_INCLUDE_DIR}")
    endif()
  endforeach()
endif()

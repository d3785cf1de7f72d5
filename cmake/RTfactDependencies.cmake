# Dependencies, all from Debian 12 packages. The order matters (README, "Build notes"):
# PCL and VTK first, then TBB, then OpenVDB with its own Find modules appended last.
macro(rtfact_find_core_dependencies)
  find_package(TBB REQUIRED)
  find_package(OpenImageIO REQUIRED)
  # OpenImageIO's exported target lists /usr/include/opencv4 even without libopencv-dev.
  get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
  list(FILTER _oiio_inc EXCLUDE REGEX "opencv")
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")
  if(RTFACT_BUILD_TESTS)
    find_package(GTest REQUIRED)
  endif()
  if(RTFACT_BUILD_BENCH)
    find_package(benchmark REQUIRED)
  endif()
endmacro()

if(RTFACT_CORE_ONLY)
  rtfact_find_core_dependencies()
  return()
endif()

# VTK (through PCL) links MPI::MPI_C.
find_package(MPI COMPONENTS C QUIET)
find_package(PCL 1.12 REQUIRED COMPONENTS common io kdtree search features)
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOCore IOGeometry IOPLY IOLegacy IOXML IOImage
             ImagingCore)
rtfact_find_core_dependencies()
find_package(embree 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_path(RTFACT_OPENVDB_MODULE_DIR FindOpenVDB.cmake PATH_SUFFIXES cmake/OpenVDB
          PATHS /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE} /usr/local/lib/${CMAKE_LIBRARY_ARCHITECTURE} /usr/lib /usr/local/lib
          NO_DEFAULT_PATH)
list(APPEND CMAKE_MODULE_PATH ${RTFACT_OPENVDB_MODULE_DIR})
find_package(OpenVDB REQUIRED)

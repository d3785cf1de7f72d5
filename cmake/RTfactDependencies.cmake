# Dependencies, all from Debian 12 packages. The order matters (see README, "Build notes"):
# PCL and VTK first, then TBB, then OpenVDB with its own Find modules.
find_package(MPI COMPONENTS C QUIET)
find_package(PCL 1.12 REQUIRED COMPONENTS common io kdtree search features)
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOCore IOGeometry IOPLY IOLegacy IOXML IOImage
             ImagingCore)
find_package(TBB REQUIRED)
find_package(OpenImageIO REQUIRED)
# OpenImageIO's exported target lists /usr/include/opencv4 even without libopencv-dev.
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
list(FILTER _oiio_inc EXCLUDE REGEX "opencv")
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")
find_package(embree 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
if(RTFACT_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(RTFACT_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()

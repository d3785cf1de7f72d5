# Compile flags for the chosen SIMD instruction set. The native vector width follows
# from the flags (see core/simd/native.h): AVX-512 16 lanes, AVX2 8, SSE4 4, scalar 1.
if(RTFACT_ISA STREQUAL "native")
  set(RTFACT_ISA_FLAGS -march=native)
elseif(RTFACT_ISA STREQUAL "avx512")
  set(RTFACT_ISA_FLAGS -march=x86-64-v4)
elseif(RTFACT_ISA STREQUAL "avx2")
  set(RTFACT_ISA_FLAGS -march=x86-64-v3)
elseif(RTFACT_ISA STREQUAL "sse4")
  set(RTFACT_ISA_FLAGS -march=x86-64-v2)
elseif(RTFACT_ISA STREQUAL "scalar")
  set(RTFACT_ISA_FLAGS -march=x86-64-v2 -DRTFACT_FORCE_SCALAR)
else()
  message(FATAL_ERROR "RTFACT_ISA must be native, avx512, avx2, sse4 or scalar (got '${RTFACT_ISA}')")
endif()
# The flags travel on two INTERFACE targets instead of being PUBLIC on the core:
#  rtfact::isa      -march and the floating-point model; PUBLIC through rtfact_core,
#                   since every consumer instantiates the core's SIMD templates.
#  rtfact::warnings our warning set (and -Werror with RTFACT_WERROR); PRIVATE on each of
#                   our own targets (rtfact_apply_warnings), never seen by a consumer.
# -ffp-contract=fast turns a*b+c into FMA.
add_library(rtfact_isa INTERFACE)
add_library(rtfact::isa ALIAS rtfact_isa)
target_compile_options(rtfact_isa INTERFACE ${RTFACT_ISA_FLAGS} -ffp-contract=fast -fno-math-errno)

add_library(rtfact_warnings INTERFACE)
add_library(rtfact::warnings ALIAS rtfact_warnings)
target_compile_options(rtfact_warnings INTERFACE -Wall -Wextra -Wno-missing-field-initializers)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # psabi: notes about vector ABI changes we never expose; the other two are false
  # positives of GCC 12 in intrinsics headers and std::string.
  target_compile_options(rtfact_warnings INTERFACE -Wno-psabi -Wno-maybe-uninitialized -Wno-restrict)
endif()
if(RTFACT_WERROR)
  target_compile_options(rtfact_warnings INTERFACE -Werror)
endif()

# Links rtfact::warnings PRIVATE to every target defined below `dir` (called once, at the
# end of the top-level CMakeLists, so no target can be forgotten).
function(rtfact_apply_warnings dir)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(t IN LISTS targets)
    get_target_property(type ${t} TYPE)
    if(type STREQUAL "STATIC_LIBRARY" OR type STREQUAL "SHARED_LIBRARY" OR type STREQUAL "MODULE_LIBRARY"
       OR type STREQUAL "EXECUTABLE" OR type STREQUAL "OBJECT_LIBRARY")
      target_link_libraries(${t} PRIVATE rtfact_warnings)
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    rtfact_apply_warnings(${sub})
  endforeach()
endfunction()

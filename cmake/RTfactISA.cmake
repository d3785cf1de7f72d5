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
# -ffp-contract=fast turns a*b+c into FMA.
set(RTFACT_CXX_FLAGS ${RTFACT_ISA_FLAGS} -ffp-contract=fast -fno-math-errno -Wall -Wextra
    -Wno-missing-field-initializers)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # psabi: notes about vector ABI changes we never expose; the other two are false
  # positives of GCC 12 in intrinsics headers and std::string.
  list(APPEND RTFACT_CXX_FLAGS -Wno-psabi -Wno-maybe-uninitialized -Wno-restrict)
endif()

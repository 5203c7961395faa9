# A precompiled header for core_tests, the target with the most sources (~75, each parsing
# GoogleTest and the same standard headers): a cold build (CI, a fresh clone) parses them once
# instead of once per source, a sixth of the target's compile time. It precompiles with the
# target's own flags, so the header always matches. Only system headers, so an edit of the
# project's headers does not rebuild the whole target. (Measured: srd_ros gains nothing, its time
# goes to code generation, not to parsing.)
#
# Off by default with ccache as the compiler launcher: ccache does not cache a source compiled with
# a precompiled header (unless told to be sloppy), and warm rebuilds matter more there.
# -DSRD_PRECOMPILED_HEADERS=ON/OFF decides either way.
if(NOT DEFINED SRD_PRECOMPILED_HEADERS)
  if(CMAKE_CXX_COMPILER_LAUNCHER MATCHES "ccache")
    set(SRD_PRECOMPILED_HEADERS OFF)
  else()
    set(SRD_PRECOMPILED_HEADERS ON)
  endif()
endif()
if(NOT SRD_PRECOMPILED_HEADERS)
  return()
endif()

if(TARGET core_tests)
  target_precompile_headers(core_tests PRIVATE
    <gtest/gtest.h> <string> <vector> <cmath> <limits> <chrono> <thread> <mutex> <memory>
    <functional> <cstdint>)
endif()

# A precompiled header for core_tests, the target with the most sources (~75, each parsing
# GoogleTest and the same standard headers): a cold build (CI, a fresh clone) parses them once
# instead of once per source, a sixth of the target's compile time. It precompiles with the
# target's own flags, so the header always matches. Only system headers, so an edit of the
# project's headers does not rebuild the whole target. (Measured: srd_ros gains nothing, its time
# goes to code generation, not to parsing.)
#
# Off by default with ccache as the compiler launcher: ccache does not cache a source compiled with
# a precompiled header (unless told to be sloppy), and warm rebuilds matter more there (so is the
# unity build of core_tests below, which would rebuild 8 sources for one edit).
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
  # And in batches of 8 sources (a unity build): their project headers are parsed once a batch,
  # and a batch took 7 CPU-s against 17.6 for its sources one by one. So a test file's own names
  # (in its anonymous namespace) must not repeat another's: such a build says so at once.
  set_target_properties(core_tests PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
endif()

# One precompiled header for every gtest that includes roscpp (the rostests' test programs and the
# ROS layer's unit tests, ~45 targets of one to four sources each): each of them spent about 4 s of
# its ~7 s parsing roscpp, its messages and GoogleTest. A target of its own builds it once and the
# others reuse it (REUSE_FROM), which needs their flags to match: all take the directory's flags
# and GoogleTest's one definition. A target whose flags differ gets GCC's fallback (the headers
# are parsed as text), never a wrong build.
set(srd_ros_test_pch_headers
  <gtest/gtest.h> <ros/ros.h> <sensor_msgs/JointState.h> <sensor_msgs/Imu.h>
  <geometry_msgs/Twist.h> <nav_msgs/Odometry.h> <std_msgs/Bool.h> <std_srvs/Trigger.h>
  <diagnostic_msgs/DiagnosticArray.h> <string> <vector> <thread> <memory> <chrono> <mutex>
  <cmath> <functional> <cstdint>)
add_library(srd_ros_test_pch OBJECT test/support/ros_test_pch.cpp)
target_include_directories(srd_ros_test_pch PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(srd_ros_test_pch PRIVATE ${GTEST_LIBRARIES})
srd_test_code_options(srd_ros_test_pch)  # cmake/test_compile_options.cmake
target_precompile_headers(srd_ros_test_pch PRIVATE ${srd_ros_test_pch_headers})

# The gtests that link roscpp (directly or through srd_ros / srd_test_support).
srd_gtest_executables(srd_roscpp_gtests "roscpp|srd_ros|srd_test_support")
foreach(target IN LISTS srd_roscpp_gtests)
  target_precompile_headers(${target} REUSE_FROM srd_ros_test_pch)
endforeach()

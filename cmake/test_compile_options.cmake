# The tests' own code compiles at -Og: the test programs (every gtest and rostest executable) and
# their helpers (srd_test_support). The code under test, srd_core, srd_ros, srd_sim and the nodes,
# keeps the build's flags (-O2 in RelWithDebInfo, what users run). The test programs only drive it,
# and optimizing their GoogleTest and roscpp template code was a third of the tests' compile time.
# -DSRD_TEST_OPTIMIZATION="" builds them with the build's flags instead.
set(SRD_TEST_OPTIMIZATION "-Og" CACHE STRING "Optimization of the test programs' own code")

function(srd_test_code_options target)
  if(SRD_TEST_OPTIMIZATION)
    target_compile_options(${target} PRIVATE ${SRD_TEST_OPTIMIZATION})
  endif()
endfunction()

# srd_gtest_executables(<out> [<regex>]): the executables that link GoogleTest and, given a regex,
# whose link libraries match it too (precompiled_headers.cmake picks the roscpp ones).
function(srd_gtest_executables out)
  set(found "")
  get_property(targets DIRECTORY PROPERTY BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    get_target_property(libraries ${target} LINK_LIBRARIES)
    if(type STREQUAL "EXECUTABLE" AND "${libraries}" MATCHES "gtest"
       AND (NOT ARGV1 OR "${libraries}" MATCHES "${ARGV1}"))
      list(APPEND found ${target})
    endif()
  endforeach()
  set(${out} ${found} PARENT_SCOPE)
endfunction()

# Every executable that links GoogleTest, and the helpers they share.
srd_gtest_executables(srd_gtests)
foreach(target IN LISTS srd_gtests)
  srd_test_code_options(${target})
endforeach()
srd_test_code_options(srd_test_support)

# The order in which `ctest -j` (.ci/run) starts the tests: the longest first, so that the parallel
# run does not end with one long test alone. COST is only an order (seconds, roughly, from a run on
# a 2-core machine); nothing asserts a time. After a run, ctest's own measurements
# (Testing/Temporary/CTestCostData.txt) take over; a test not listed here keeps its place.
function(srd_test_cost type file seconds)
  string(REPLACE "/" "_" name "${file}")
  set(test "_ctest_${PROJECT_NAME}_${type}_${name}")
  if(TEST "${test}")
    set_tests_properties("${test}" PROPERTIES COST ${seconds})
  endif()
endfunction()

srd_test_cost(rostest test/rostest/soak.test 66)
srd_test_cost(rostest src/devices/servo_bus/test/ros/servo_estop.test 34)
srd_test_cost(rostest test/rostest/trajectory.test 28)
srd_test_cost(rostest src/devices/servo_bus/test/ros/bus_yield.test 27)
srd_test_cost(rostest src/devices/base/test/ros/calibrate_base.test 25)
srd_test_cost(rostest test/rostest/base_node.test 24)
srd_test_cost(rostest src/devices/body/test/ros/gyro_calibration.test 24)
srd_test_cost(gtest core_tests 20)
srd_test_cost(rostest test/rostest/tcp_port.test 20)
srd_test_cost(rostest test/rostest/replay.test 16)
srd_test_cost(rostest test/rostest/estop_bus.test 15)
srd_test_cost(rostest test/rostest/faults.test 14)
srd_test_cost(rostest test/rostest/ros_interface_fuzz.test 12)
srd_test_cost(rostest test/rostest/odom.test 11)
srd_test_cost(rostest test/rostest/trajectory_stop.test 11)

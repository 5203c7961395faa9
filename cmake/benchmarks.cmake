# End-to-end benchmarks of driver_node over pseudo-terminals and a private roscore. They print
# numbers (bench/run_benchmarks.sh) and are never part of the test suite.
add_executable(driver_bench
  bench/bench_support.cpp
  bench/driver_bench.cpp
  bench/ros_bench_support.cpp
  test/support/pty_frame_reader.cpp)  # the tests' pty reader; srd_test_support exists only with tests
target_include_directories(driver_bench PRIVATE ${PROJECT_SOURCE_DIR}/test ${catkin_INCLUDE_DIRS})
target_link_libraries(driver_bench srd_core srd_sim ${catkin_LIBRARIES})

# The same node reading its ports once per ~read_poll_interval: the polling side of section 7.
add_executable(polling_driver_node bench/polling_driver_node_main.cpp bench/polling_stream.cpp)
target_include_directories(polling_driver_node PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(polling_driver_node srd_ros)

# The benchmark launches these executables, so building it builds them.
add_dependencies(driver_bench driver_node polling_driver_node robot_sim
  ${PROJECT_NAME}_generate_messages_cpp)
# Benchmarks are run from the build tree and never installed (hence the catkin_lint pragma).
#catkin_lint: ignore uninstalled_script

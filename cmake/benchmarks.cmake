# End-to-end benchmarks of driver_node over pseudo-terminals and a private roscore. They print
# numbers (bench/run_benchmarks.sh) and are never part of the test suite.
add_executable(driver_bench
  bench/bench_support.cpp
  bench/driver_bench.cpp
  bench/ros_bench_support.cpp
  test/support/pty_frame_reader.cpp)  # the tests' pty reader; srd_test_support exists only with tests
target_include_directories(driver_bench PRIVATE ${PROJECT_SOURCE_DIR}/test ${catkin_INCLUDE_DIRS})
target_link_libraries(driver_bench srd_core ${catkin_LIBRARIES})
# The benchmark launches these executables, so building it builds them.
add_dependencies(driver_bench driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)

install(TARGETS driver_bench RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(PROGRAMS bench/run_benchmarks.sh DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

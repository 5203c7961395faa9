# End-to-end benchmarks of driver_node over pseudo-terminals and a private roscore. They print
# numbers (bench/run_benchmarks.sh), are never part of the test suite and are not installed.
# Included only with -DSRD_BUILD_BENCHMARKS=ON.
find_package(benchmark QUIET)
if(benchmark_FOUND)
  add_executable(bench_framer bench/bench_framer.cpp)
  target_include_directories(bench_framer PRIVATE ${PROJECT_SOURCE_DIR}/test)  # support/framer_configs.h
  target_link_libraries(bench_framer srd_core srd_sim benchmark::benchmark)
endif()

# What driver_node's port reader and base loop spend per wake-up to wait their way (wakeable by
# stop and commands) against the floor's blocking read and clock_nanosleep.
add_executable(bench_wait bench/bench_wait.cpp)
target_link_libraries(bench_wait srd_core srd_sim)

# The floor: the least a roscpp driver of this robot must do, driver_bench's yardstick.
add_executable(floor_node bench/floor_node.cpp bench/floor_interface.cpp)
target_include_directories(floor_node PRIVATE ${PROJECT_SOURCE_DIR}/test ${catkin_INCLUDE_DIRS})
target_link_libraries(floor_node srd_core ${catkin_LIBRARIES})
# Its ~same_interface includes this package's messages, action and dynamic_reconfigure headers.
add_dependencies(floor_node ${PROJECT_NAME}_generate_messages_cpp ${PROJECT_NAME}_gencfg
  ${catkin_EXPORTED_TARGETS})

# The servo bus's floor: one blocking READ_ANGLE client (driver_bench section 10); with --publish
# it also publishes each answer on servo_states through roscpp.
add_executable(servo_floor bench/servo_floor.cpp)
target_include_directories(servo_floor PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(servo_floor srd_core ${catkin_LIBRARIES})

# How often roscpp loses a service call on a busy machine, by way of connecting
# (bench/service_call_loss.sh): why the tests call services through test_support::callService.
add_executable(service_call_loss bench/service_call_loss.cpp)
target_include_directories(service_call_loss PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(service_call_loss ${catkin_LIBRARIES})

add_executable(driver_bench
  bench/bench_support.cpp
  bench/driver_bench.cpp
  bench/robot_end.cpp
  bench/ros_bench_support.cpp
  test/support/pty_frame_reader.cpp)  # the tests' pty reader; srd_test_support exists only with tests
target_include_directories(driver_bench PRIVATE ${PROJECT_SOURCE_DIR}/test ${catkin_INCLUDE_DIRS})
target_link_libraries(driver_bench srd_core srd_sim ${catkin_LIBRARIES})

# The same node reading its ports once per ~read_poll_interval: the polling side of section 7.
add_executable(polling_driver_node bench/polling_driver_node_main.cpp bench/polling_stream.cpp)
target_include_directories(polling_driver_node PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(polling_driver_node srd_ros)

# The benchmark launches these executables, so building it builds them.
add_dependencies(driver_bench driver_node polling_driver_node floor_node robot_sim servo_floor
  ${PROJECT_NAME}_generate_messages_cpp)
# The ROS 2 front end's cost and latency (bench/run_benchmarks.sh --dds), with Cyclone DDS only.
# It receives as the DDS tests' second participant does (test/dds_front/ros2_peer.*, which reports
# through gtest's EXPECTs).
if(SRD_WITH_DDS)
  add_executable(dds_bench
    bench/dds_bench.cpp
    bench/bench_support.cpp
    bench/ros_bench_support.cpp
    test/dds_front/ros2_peer.cpp)
  target_include_directories(dds_bench PRIVATE ${PROJECT_SOURCE_DIR}/test ${catkin_INCLUDE_DIRS})
  target_link_libraries(dds_bench srd_core srd_sim srd_dds gtest ${catkin_LIBRARIES})
  add_dependencies(dds_bench driver_node dds_driver)
endif()

# Benchmarks run from the build tree and are never installed (hence the catkin_lint pragmas).
#catkin_lint: ignore uninstalled_target
#catkin_lint: ignore uninstalled_script

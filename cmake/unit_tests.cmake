# GoogleTest unit tests of the ROS-free core and simulator (no roscore needed).
catkin_add_gtest(core_tests
  test/unit/test_base_codec.cpp
  test/unit/test_body_codec.cpp
  test/unit/test_servo_bus_codec.cpp
  test/unit/test_servo_commands.cpp
  test/unit/test_servo_params.cpp
  test/unit/test_stream_framer.cpp
  test/unit/test_diff_drive.cpp
  test/unit/test_odometry.cpp
  test/unit/test_transport.cpp
  test/unit/test_recorded_stream.cpp
  test/unit/test_serial_link.cpp
  test/unit/test_base_controller.cpp
  test/unit/test_body_controller.cpp
  test/unit/test_servo_bus_client.cpp
  test/unit/test_servo_bus.cpp
  test/unit/test_sim.cpp
  test/unit/test_device_set.cpp)
target_include_directories(core_tests PRIVATE ${PROJECT_SOURCE_DIR}/test)  # support/test_helpers.h
target_link_libraries(core_tests srd_core srd_sim gtest_main)
# test_device_set.cpp reads config/analyzers.yaml from the sources.
target_compile_definitions(core_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# Conversions and parameter validation of the ROS layer (pure functions, no roscore needed).
catkin_add_gtest(ros_layer_tests
  test/unit/test_conversions.cpp
  test/unit/test_driver_params.cpp
  test/unit/test_bag_replay.cpp)
target_include_directories(ros_layer_tests PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(ros_layer_tests srd_ros gtest_main)

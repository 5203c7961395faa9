# GoogleTest unit tests of the ROS-free core and simulator (no roscore needed): these, and every
# device's own (src/devices/<name>/test/*.cpp).
srd_device_sources(test srd_device_unit_tests)
catkin_add_gtest(core_tests
  ${srd_device_unit_tests}
  test/unit/test_stream_framer_golden_frames.cpp
  test/unit/test_stream_framer_streams.cpp
  test/unit/test_stream_framer_broken_frames.cpp
  test/unit/test_stream_framer_buffering.cpp
  test/unit/test_stream_framer_random_junk.cpp
  test/unit/test_diff_drive.cpp
  test/unit/test_odometry.cpp
  test/unit/test_driver_core.cpp
  test/unit/test_transport_pty_io.cpp
  test/unit/test_transport_errors_and_links.cpp
  test/unit/test_transport_baud_and_lock.cpp
  test/unit/test_transport_tcp.cpp
  test/unit/test_read_waiter.cpp
  test/unit/test_recorded_stream.cpp
  test/unit/test_recording_replay.cpp
  test/unit/test_capture_queue.cpp
  test/unit/test_params_in_force.cpp
  test/unit/test_stop_signals.cpp
  test/unit/test_serial_link.cpp
  test/unit/test_realtime.cpp
  test/unit/test_scheduler_slice.cpp
  test/unit/test_sim_device_models.cpp
  test/unit/test_sim_pty_devices.cpp
  test/unit/test_sim_whole_robot.cpp
  test/unit/test_sim_command_line.cpp
  test/unit/test_sim_registry.cpp
  test/unit/test_device_registry.cpp
  test/unit/test_device_sections.cpp
  test/unit/test_e_stop.cpp
  test/unit/test_input_refusals.cpp
  test/unit/test_log.cpp
  test/unit/test_guarded_call.cpp
  test/unit/test_status_report.cpp
  test/unit/test_capabilities.cpp
  test/unit/test_event_rate.cpp
  test/unit/test_loop_wake.cpp
  test/unit/test_swapped_value.cpp)
target_include_directories(core_tests PRIVATE ${PROJECT_SOURCE_DIR}/test)  # support/test_helpers.h
target_link_libraries(core_tests srd_core srd_sim gtest_main)
# test_device_registry.cpp reads config/analyzers.yaml from the sources.
target_compile_definitions(core_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# The parameter docs (docs/node_api.md's tables, config/robot.yaml) against the parameter table.
catkin_add_gtest(param_docs_tests test/unit/test_param_docs.cpp)
target_include_directories(param_docs_tests PRIVATE ${YAML_CPP_INCLUDE_DIR})
target_link_libraries(param_docs_tests srd_core ${YAML_CPP_LIBRARIES} gtest_main)
target_compile_definitions(param_docs_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# A parameter file through the parameter table (dds_driver --config, robot_description).
catkin_add_gtest(yaml_params_tests test/unit/test_yaml_params.cpp)
target_link_libraries(yaml_params_tests srd_yaml_params gtest_main)
target_compile_definitions(yaml_params_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

# Conversions and parameter validation of the ROS layer (pure functions, no roscore needed).
catkin_add_gtest(ros_layer_tests
  test/unit/test_conversions.cpp
  test/unit/test_driver_params.cpp
  test/unit/test_bag_replay.cpp
  test/unit/test_guarded_callbacks.cpp)
target_include_directories(ros_layer_tests PRIVATE ${catkin_INCLUDE_DIRS} ${PROJECT_SOURCE_DIR}/test)
target_link_libraries(ros_layer_tests srd_ros gtest_main)

# The robot description: robot_description's URDF through check_urdf and urdf::Model.
find_package(urdf REQUIRED)
catkin_add_gtest(description_tests test/unit/test_robot_description.cpp
  test/unit/test_robot_description_command.cpp)
target_include_directories(description_tests PRIVATE ${catkin_INCLUDE_DIRS} ${urdf_INCLUDE_DIRS})
target_link_libraries(description_tests srd_description ${urdf_LIBRARIES} gtest_main)
target_compile_definitions(description_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
  SRD_ROBOT_DESCRIPTION="$<TARGET_FILE:robot_description>")
add_dependencies(description_tests robot_description)
# The IMU's heading fused into odometry (~base/use_imu_heading), ROS-free.
catkin_add_gtest(heading_fusion_tests test/unit/test_heading_fusion.cpp)
target_link_libraries(heading_fusion_tests srd_core gtest_main)
# follow_joint_trajectory keeps control_msgs' md5 sums.
catkin_add_gtest(trajectory_action_definition_tests test/unit/test_trajectory_action_definition.cpp)
target_include_directories(trajectory_action_definition_tests PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(trajectory_action_definition_tests ${catkin_LIBRARIES} gtest_main)
add_dependencies(trajectory_action_definition_tests ${PROJECT_NAME}_generate_messages_cpp)

# The ROS-free trajectory core: interpolation, replacement, goal validation, tolerances, the joint
# groups and the executor (goals, ticks, stops) on a clock the tests step.
catkin_add_gtest(trajectory_tests test/unit/test_trajectory.cpp
  test/unit/test_trajectory_joints.cpp
  test/unit/test_trajectory_executor.cpp
  test/unit/test_trajectory_executor_start.cpp
  test/unit/test_trajectory_message_time.cpp)
target_link_libraries(trajectory_tests srd_core gtest_main)
# support/trajectory_executor_rig.h
target_include_directories(trajectory_tests PRIVATE ${PROJECT_SOURCE_DIR}/test)

# Trajectories' ROS-side pure functions (messages, bus joints from parameters, stamps); no roscore.
catkin_add_gtest(trajectory_ros_tests test/unit/test_trajectory_ros.cpp)
target_include_directories(trajectory_ros_tests PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(trajectory_ros_tests srd_ros gtest_main)

# Runtime tuning: the dynamic_reconfigure .cfg files agree with the parameter table, and what of a
# change applies (no roscore needed).
catkin_add_gtest(runtime_tuning_tests test/unit/test_runtime_tuning.cpp)
target_include_directories(runtime_tuning_tests PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(runtime_tuning_tests srd_ros gtest_main)
add_dependencies(runtime_tuning_tests ${PROJECT_NAME}_gencfg)
# It finds the .cfg files in the sources (each device's src/devices/<name>/ros/, cfg/).
target_compile_definitions(runtime_tuning_tests PRIVATE SRD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

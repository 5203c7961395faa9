# rostest integration tests: driver_node (and robot_sim) against pseudo-terminals, checked through
# ROS topics/services and the raw bytes on the pty.

# The helpers every rostest shares (test/support/): ROS-free ones (pty reader, child processes,
# /proc readers, polling) and ROS ones (topic counters, diagnostics, the node's pid, main()).
add_library(srd_test_support STATIC
  test/support/pty_frame_reader.cpp
  test/support/fake_device.cpp
  test/support/process_support.cpp
  test/support/ros_test_support.cpp
  test/support/pty_tap.cpp)
target_include_directories(srd_test_support PUBLIC ${PROJECT_SOURCE_DIR}/test
  PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(srd_test_support PUBLIC srd_core srd_sim ${catkin_LIBRARIES})
add_dependencies(srd_test_support ${PROJECT_NAME}_generate_messages_cpp)

# Behaviours in several sources of one target: one .test, one ROS master and one driver_node.
add_rostest_gtest(test_base_node test/rostest/base_node.test
  test/rostest/test_base_node_driving.cpp
  test/rostest/test_base_node_resets_and_status.cpp
  test/rostest/test_base_node_process.cpp)
target_include_directories(test_base_node PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_base_node srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_base_node driver_node ${PROJECT_NAME}_generate_messages_cpp)

add_rostest_gtest(test_body_node test/rostest/body_node.test
  test/rostest/test_body_node_telemetry.cpp
  test/rostest/test_body_node_commands.cpp
  test/rostest/test_body_node_sim.cpp)
target_include_directories(test_body_node PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_body_node srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_body_node driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)

add_rostest_gtest(test_servo_bus_node test/rostest/servo_bus_node.test
  test/rostest/test_servo_bus_node_reads_and_writes.cpp
  test/rostest/test_servo_bus_node_motion.cpp
  test/rostest/test_servo_bus_node_rejections.cpp
  test/rostest/test_servo_bus_node_armed.cpp)
target_include_directories(test_servo_bus_node PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_servo_bus_node srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_servo_bus_node driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)


# driver.launch's parameter precedence (config file vs port:= / baud:=), through roslaunch.
add_rostest_gtest(test_launch_precedence test/rostest/launch_precedence.test
  test/rostest/test_launch_precedence.cpp)
target_include_directories(test_launch_precedence PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_launch_precedence srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_launch_precedence driver_node)

# config/analyzers.yaml against the driver's real statuses, through diagnostic_aggregator's library.
find_package(diagnostic_aggregator REQUIRED)
add_rostest_gtest(test_analyzers test/rostest/analyzers.test test/rostest/test_analyzers.cpp)
target_include_directories(test_analyzers PRIVATE ${catkin_INCLUDE_DIRS} ${diagnostic_aggregator_INCLUDE_DIRS})
target_link_libraries(test_analyzers srd_test_support ${diagnostic_aggregator_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(test_analyzers driver_node robot_sim)

# Capture and replay round trip: a live capture under faults, replayed from a bag, compared message
# by message.
add_rostest_gtest(test_replay test/rostest/replay.test test/rostest/test_replay.cpp)
target_include_directories(test_replay PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_replay srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_replay driver_node ${PROJECT_NAME}_generate_messages_cpp)

# serial_robot_driver/DriverNodelet in a manager: driving, unloading and a stopped manager.
add_rostest_gtest(test_nodelet test/rostest/nodelet.test test/rostest/test_nodelet.cpp)
target_include_directories(test_nodelet PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_nodelet srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_nodelet srd_nodelet ${PROJECT_NAME}_generate_messages_cpp)

# Two processes on one port: the second is told "port busy" (and by whom); the first is unharmed.
add_rostest_gtest(test_port_busy test/rostest/port_busy.test test/rostest/test_port_busy.cpp)
target_include_directories(test_port_busy PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_port_busy srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_port_busy driver_node ${PROJECT_NAME}_generate_messages_cpp)

add_rostest_gtest(test_servo_topics test/rostest/servo_topics.test
  test/rostest/test_servo_topics.cpp)
target_include_directories(test_servo_topics PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_servo_topics srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_servo_topics driver_node ${PROJECT_NAME}_generate_messages_cpp)

# Commanded-motion odometry, tf and the e-stop against the simulated base (sim::RobotSim in-process).
add_rostest_gtest(test_odom test/rostest/odom.test test/rostest/test_odom.cpp)
target_include_directories(test_odom PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_odom srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_odom driver_node ${PROJECT_NAME}_generate_messages_cpp)

# A port reached over TCP (tcp://): driver_node against sim::RobotSim serving the base on a
# loopback socket, through the server dropping the connection and coming back.
add_rostest_gtest(test_tcp_port test/rostest/tcp_port.test test/rostest/test_tcp_port.cpp)
target_include_directories(test_tcp_port PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_tcp_port srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_tcp_port driver_node ${PROJECT_NAME}_generate_messages_cpp)

# sim.launch + description.launch: every link of the description on tf, wheel_states against odom.
# (urdf: found in unit_tests.cmake, included first.)
add_rostest_gtest(test_description test/rostest/description.test test/rostest/test_description.cpp)
target_include_directories(test_description PRIVATE ${catkin_INCLUDE_DIRS} ${urdf_INCLUDE_DIRS})
target_link_libraries(test_description srd_test_support ${urdf_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(test_description driver_node robot_sim robot_description)

# fleet_sim.launch: two robots in namespaces on one master, apart in topics, services and tf.
add_rostest_gtest(test_fleet_sim test/rostest/fleet_sim.test test/rostest/test_fleet_sim.cpp)
target_include_directories(test_fleet_sim PRIVATE ${catkin_INCLUDE_DIRS} ${urdf_INCLUDE_DIRS}
  ${diagnostic_aggregator_INCLUDE_DIRS})
target_link_libraries(test_fleet_sim srd_test_support ${urdf_LIBRARIES}
  ${diagnostic_aggregator_LIBRARIES} ${catkin_LIBRARIES})
add_dependencies(test_fleet_sim driver_node robot_sim robot_description
  ${PROJECT_NAME}_generate_messages_cpp)
# ~base/use_imu_heading end to end: odom's yaw against simulated robots whose base slips while
# turning (sim::RobotSim in-process), with and without the IMU, and without telemetry.
add_rostest_gtest(test_imu_heading test/rostest/imu_heading.test test/rostest/test_imu_heading.cpp)
target_include_directories(test_imu_heading PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_imu_heading srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_imu_heading driver_node ${PROJECT_NAME}_generate_messages_cpp)
# follow_joint_trajectory (every result code, cancel, preemption, take-over, telemetry lost) and
# joint_trajectory against the simulated body (sim::RobotSim in-process).
add_rostest_gtest(test_trajectory test/rostest/trajectory.test test/rostest/test_trajectory.cpp)
target_include_directories(test_trajectory PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_trajectory srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_trajectory driver_node ${PROJECT_NAME}_generate_messages_cpp)
# What trajectory stops write (an empty trajectory with and without telemetry, a cancel of a fast
# bus joint) and a retune of the bus poll, on the wire: a fake board and the simulated bus behind a
# tap (test_support::PtyTap).
add_rostest_gtest(test_trajectory_stop test/rostest/trajectory_stop.test
  test/rostest/test_trajectory_stop.cpp)
target_include_directories(test_trajectory_stop PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_trajectory_stop srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_trajectory_stop driver_node ${PROJECT_NAME}_generate_messages_cpp)
# A body goal while the ROS clock (use_sim_time, /clock from the test) steps forward and back: the
# sync-writes on the wire progress smoothly and the goal succeeds.
add_rostest_gtest(test_trajectory_clock test/rostest/trajectory_clock.test
  test/rostest/test_trajectory_clock.cpp)
target_include_directories(test_trajectory_clock PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_trajectory_clock srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_trajectory_clock driver_node ${PROJECT_NAME}_generate_messages_cpp)
# Parameters an earlier launch left on the master (a ~replay_bag, a disabled device) do not steer
# driver.launch (node and nodelet) or sim.launch: each clears its private namespace first.
add_rostest_gtest(test_stale_params test/rostest/stale_params.test
  test/rostest/test_stale_params.cpp)
target_include_directories(test_stale_params PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_stale_params srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_stale_params driver_node robot_sim srd_nodelet)

# Runtime tuning through dynamic_reconfigure's Python client against robot_sim.
add_rostest(test/rostest/runtime_tuning.test
  DEPENDENCIES driver_node robot_sim ${PROJECT_NAME}_generate_messages_py ${PROJECT_NAME}_gencfg)
# Safe motion: the e-stop with a spinning bus servo, servo/relax and servo/hold, the servos'
# stop on SIGINT and on a nodelet unload (sim::RobotSim in-process).
add_rostest_gtest(test_safe_motion test/rostest/safe_motion.test test/rostest/test_safe_motion.cpp)
target_include_directories(test_safe_motion PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_safe_motion srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_safe_motion driver_node srd_nodelet ${PROJECT_NAME}_generate_messages_cpp)
# serial_raw with a subscriber that stops reading: bounded memory, the capture's drop counter in its
# diagnostic status, and a true count (WireCapture in-process, a raw TCPROS subscriber).
add_rostest_gtest(test_wire_capture test/rostest/wire_capture.test
  test/rostest/test_wire_capture.cpp)
target_include_directories(test_wire_capture PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_wire_capture srd_ros srd_test_support ${catkin_LIBRARIES})
add_dependencies(test_wire_capture ${PROJECT_NAME}_generate_messages_cpp)
# The e-stop with the bus busy, the cable out and a stop lost: nothing moves after it, the stop
# goes first after the replug and is written again until the servo rests, the base keeps its pace.
add_rostest_gtest(test_estop_bus test/rostest/estop_bus.test test/rostest/test_estop_bus.cpp)
target_include_directories(test_estop_bus PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_estop_bus srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_estop_bus driver_node ${PROJECT_NAME}_generate_messages_cpp)
# The ROS interface fuzzer: seeded extreme inputs on every topic and service, part of them under the
# e-stop, with a bus servo spinning; the node must live on and write no motion frame under the
# e-stop (SRD_FUZZ_SEED / SRD_FUZZ_COUNT, scripts/fuzz_ros_interface.sh for a long run).
add_rostest_gtest(test_ros_interface_fuzz test/rostest/ros_interface_fuzz.test
  test/rostest/test_ros_interface_fuzz.cpp test/support/ros_fuzz_inputs.cpp)
target_include_directories(test_ros_interface_fuzz PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_ros_interface_fuzz srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_ros_interface_fuzz driver_node ${PROJECT_NAME}_generate_messages_cpp)

# Each device's own rostests, found by convention: src/devices/<name>/test/ros/<x>.test and the
# gtest sources beside it named test_<x>*.cpp make the target test_<x> (run with
# `rostest --text serial_robot_driver <x>.test`), against driver_node and robot_sim.
foreach(device ${SRD_DEVICES})
  file(GLOB device_rostests RELATIVE "${PROJECT_SOURCE_DIR}" CONFIGURE_DEPENDS
    "${PROJECT_SOURCE_DIR}/src/devices/${device}/test/ros/*.test")
  foreach(launch ${device_rostests})
    get_filename_component(stem "${launch}" NAME_WE)
    get_filename_component(folder "${launch}" DIRECTORY)
    file(GLOB sources RELATIVE "${PROJECT_SOURCE_DIR}" CONFIGURE_DEPENDS
      "${PROJECT_SOURCE_DIR}/${folder}/test_${stem}*.cpp")
    list(SORT sources)
    add_rostest_gtest(test_${stem} ${launch} ${sources})
    target_include_directories(test_${stem} PRIVATE ${catkin_INCLUDE_DIRS})
    target_link_libraries(test_${stem} srd_test_support srd_sim ${catkin_LIBRARIES})
    # calibrate_base: the base's calibration rostest runs the tool as a user does.
    add_dependencies(test_${stem} driver_node robot_sim calibrate_base
      ${PROJECT_NAME}_generate_messages_cpp)
  endforeach()
endforeach()

# driver_node with ~ros2/enabled: one process on both graphs (only with Cyclone DDS).
if(SRD_WITH_DDS)
  add_rostest_gtest(test_ros2_graph test/rostest/ros2_graph.test
    test/rostest/test_ros2_graph.cpp
    test/dds_front/hostile_dds_inputs.cpp
    test/dds_front/ros2_peer.cpp)
  target_include_directories(test_ros2_graph PRIVATE ${catkin_INCLUDE_DIRS})
  target_link_libraries(test_ros2_graph srd_test_support srd_dds ${catkin_LIBRARIES})
  add_dependencies(test_ros2_graph driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)
endif()

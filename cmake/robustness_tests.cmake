# Robustness rostests: driver_node against the simulator on pseudo-terminals in every port layout,
# through 100 unplug/replug cycles, with extreme inputs, and in a soak under injected faults.
# The soak runs 60 s; SRD_SOAK_SECONDS=<s> in the environment runs it longer on demand.
add_rostest_gtest(test_multi_port test/rostest/multi_port.test test/rostest/test_multi_port.cpp)
target_include_directories(test_multi_port PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_multi_port srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_multi_port driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)

add_rostest_gtest(test_faults test/rostest/faults.test test/rostest/test_faults_unplug_replug.cpp
  test/rostest/test_faults_extreme_commands.cpp test/rostest/test_faults_extreme_servo_requests.cpp)
target_include_directories(test_faults PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_faults srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_faults driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)

add_rostest_gtest(test_soak test/rostest/soak.test test/rostest/test_soak.cpp)
target_include_directories(test_soak PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_soak srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_soak driver_node robot_sim ${PROJECT_NAME}_generate_messages_cpp)

# Servo-bus stress: a few hundred service calls (some to offline servos) on the port shared with
# the base and 100 Hz telemetry, counting that the wheel heartbeat and the telemetry never lapse.
add_rostest_gtest(test_servo_stress test/rostest/servo_stress.test
                  test/rostest/test_servo_stress.cpp)
target_include_directories(test_servo_stress PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(test_servo_stress srd_test_support srd_sim ${catkin_LIBRARIES})
add_dependencies(test_servo_stress driver_node ${PROJECT_NAME}_generate_messages_cpp)

# The base's own executables (included by srd_include_device_cmake, cmake/devices.cmake).

# calibrate_base: the turning calibration, a client of the running node's topics
# (docs/calibration.md).
add_executable(calibrate_base
  src/devices/base/ros/calibrate_base/calibrate_base_main.cpp
  src/devices/base/ros/calibrate_base/calibrate_base_client.cpp)
target_include_directories(calibrate_base PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(calibrate_base srd_ros)
add_dependencies(calibrate_base ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS calibrate_base RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# The driver on a ROS 2 graph (issue 42): the core's DDS front end (src/dds_front/: the node's own
# topics, dds_driver's runner; each device's src/devices/<name>/dds/, registered like its ros/) on
# srd_dds, and the dds_driver executable. Included only when cmake/dds.cmake found Cyclone DDS.
srd_device_sources(dds srd_device_dds_sources)
srd_write_registry("${PROJECT_BINARY_DIR}/srd_generated/registered_dds_front_ends.cpp"
  "serial_robot_driver/dds_front/dds_device_module.h"
  "serial_robot_driver::dds_front::DdsDeviceModule" kDdsModule
  "serial_robot_driver::dds_front::registeredDdsFrontEnds" dds)
# ROS-1-free: no catkin include path, no catkin library.
add_library(srd_dds_front STATIC
  ${srd_device_dds_sources}
  "${PROJECT_BINARY_DIR}/srd_generated/registered_dds_front_ends.cpp"
  src/dds_front/dds_conversions.cpp
  src/dds_front/dds_node.cpp
  src/dds_front/run_dds_driver.cpp
  src/dds_front/trajectory_loop.cpp)
target_link_libraries(srd_dds_front PUBLIC srd_core srd_dds srd_yaml_params)
set_target_properties(srd_dds_front PROPERTIES POSITION_INDEPENDENT_CODE ON)

# driver_node serves the ROS 2 graph too with ~ros2/enabled (dds_front/ros2_graph.h).
target_link_libraries(srd_ros PUBLIC srd_dds_front)

add_executable(dds_driver src/nodes/dds_driver_main.cpp)
target_link_libraries(dds_driver srd_dds_front)
install(TARGETS dds_driver RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(dds_front_tests test/dds_front/test_dds_conversions.cpp)
  target_link_libraries(dds_front_tests srd_dds_front gtest_main)
  # dds_driver against robot_sim, seen from a second participant (plain Cyclone) as a ROS 2
  # machine sees it.
  catkin_add_gtest(dds_driver_tests
    test/dds_front/test_dds_driver.cpp
    test/dds_front/hostile_dds_inputs.cpp
    test/dds_front/ros2_peer.cpp
    test/support/process_support.cpp)
  target_include_directories(dds_driver_tests PRIVATE ${PROJECT_SOURCE_DIR}/test)
  target_link_libraries(dds_driver_tests srd_dds srd_sim gtest_main)
  target_compile_definitions(dds_driver_tests PRIVATE SRD_DDS_DRIVER="$<TARGET_FILE:dds_driver>")
  add_dependencies(dds_driver_tests dds_driver)
endif()

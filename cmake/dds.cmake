# ROS 2 through DDS (issue 42; INTERFACE.md "ROS 2 (through DDS)"): optional.
# With Debian's Cyclone DDS (cyclonedds-dev; idlc from cyclonedds-tools) and libcrypto (libssl-dev:
# the SHA-256 of the REP-2011 type hashes), the ROS-free library srd_dds is built: the ROS 2 message
# types compiled by idlc from dds/idl/, the type hashes, ROS 2's naming/QoS/discovery conventions
# and the typed participant, publisher and subscription. Without them everything else builds as
# before. The CMake variable SRD_WITH_DDS says which; C++ code that links srd_dds sees the compile
# definition SRD_WITH_DDS (`#ifdef SRD_WITH_DDS`). Nothing else's compile flags change (ccache).
find_package(CycloneDDS QUIET)
find_package(OpenSSL QUIET COMPONENTS Crypto)
find_program(SRD_IDLC idlc)
if(CycloneDDS_FOUND AND OPENSSL_FOUND AND SRD_IDLC)
  set(SRD_WITH_DDS ON)
else()
  set(SRD_WITH_DDS OFF)
  message(STATUS "${PROJECT_NAME}: building WITHOUT the ROS 2 (DDS) front end: it needs "
    "Cyclone DDS and its idlc (apt install cyclonedds-dev cyclonedds-tools) and libcrypto (libssl-dev); "
    "scripts/install_deps.sh installs them")
  return()
endif()

# Every ROS 2 type the DDS layer speaks: <package>/msg/<Type>, one IDL file each (dds/idl/).
set(SRD_DDS_TYPES
  builtin_interfaces/msg/Time builtin_interfaces/msg/Duration
  std_msgs/msg/Header std_msgs/msg/Bool
  geometry_msgs/msg/Vector3 geometry_msgs/msg/Point geometry_msgs/msg/Quaternion
  geometry_msgs/msg/Pose geometry_msgs/msg/PoseWithCovariance geometry_msgs/msg/Twist
  geometry_msgs/msg/TwistWithCovariance geometry_msgs/msg/TwistStamped geometry_msgs/msg/Transform
  geometry_msgs/msg/TransformStamped
  sensor_msgs/msg/JointState sensor_msgs/msg/Imu sensor_msgs/msg/BatteryState
  nav_msgs/msg/Odometry tf2_msgs/msg/TFMessage
  diagnostic_msgs/msg/KeyValue diagnostic_msgs/msg/DiagnosticStatus
  diagnostic_msgs/msg/DiagnosticArray
  trajectory_msgs/msg/JointTrajectoryPoint trajectory_msgs/msg/JointTrajectory
  rmw_dds_common/msg/Gid rmw_dds_common/msg/NodeEntitiesInfo
  rmw_dds_common/msg/ParticipantEntitiesInfo)

# idlc at build time: dds/idl/<pkg>/msg/<Type>.idl ->
# <build>/srd_dds_generated/<pkg>/msg/<Type>.{c,h}
# (final extensibility and no XTypes type information, as rmw_cyclonedds' own types: peers match
# on the type name alone).
set(SRD_DDS_IDL_DIR ${PROJECT_SOURCE_DIR}/dds/idl)
set(SRD_DDS_GENERATED_DIR ${PROJECT_BINARY_DIR}/srd_dds_generated)
file(GLOB_RECURSE SRD_DDS_IDL_FILES CONFIGURE_DEPENDS ${SRD_DDS_IDL_DIR}/*.idl)
set(SRD_DDS_GENERATED_SOURCES "")
foreach(type ${SRD_DDS_TYPES})
  set(out_c ${SRD_DDS_GENERATED_DIR}/${type}.c)
  add_custom_command(
    OUTPUT ${out_c} ${SRD_DDS_GENERATED_DIR}/${type}.h
    COMMAND ${CMAKE_COMMAND} -E make_directory ${SRD_DDS_GENERATED_DIR}
    COMMAND ${SRD_IDLC} -x final -t -b ${SRD_DDS_IDL_DIR} -I ${SRD_DDS_IDL_DIR}
            -o ${SRD_DDS_GENERATED_DIR} ${SRD_DDS_IDL_DIR}/${type}.idl
    DEPENDS ${SRD_DDS_IDL_FILES}
    COMMENT "idlc ${type}.idl"
    VERBATIM)
  list(APPEND SRD_DDS_GENERATED_SOURCES ${out_c})
endforeach()

# ROS-free and ROS-1-free: no catkin include path, no catkin library.
add_library(srd_dds STATIC
  src/dds/cdr.cpp
  src/dds/discovery_info.cpp
  src/dds/dispatch_thread.cpp
  src/dds/domain_lease.cpp
  src/dds/endpoint.cpp
  src/dds/participant.cpp
  src/dds/ros_conventions.cpp
  src/dds/type_descriptions.cpp
  src/dds/type_hash.cpp
  ${SRD_DDS_GENERATED_SOURCES})
# The generated headers are part of srd_dds' interface (the message structs); they exist once idlc ran.
#catkin_lint: ignore_once missing_directory
#catkin_lint: ignore_once external_interface_path
target_include_directories(srd_dds PUBLIC ${SRD_DDS_GENERATED_DIR})
target_compile_definitions(srd_dds PUBLIC SRD_WITH_DDS=1)
target_link_libraries(srd_dds PUBLIC CycloneDDS::ddsc Threads::Threads PRIVATE OpenSSL::Crypto)
set_target_properties(srd_dds PROPERTIES POSITION_INDEPENDENT_CODE ON)

if(CATKIN_ENABLE_TESTING)
  # Type hashes, golden CDR bytes, the conventions' pure functions (no network).
  catkin_add_gtest(dds_tests
    test/dds/test_type_hash.cpp
    test/dds/test_cdr_golden.cpp
    test/dds/test_cdr_golden_navigation.cpp
    test/dds/test_ros_conventions.cpp
    test/dds/test_loopback.cpp)
  target_link_libraries(dds_tests srd_dds gtest_main)
  # A second participant (plain Cyclone, this process) discovers a node that dds_test_peer (another
  # process) makes with the wrappers.
  add_executable(dds_test_peer test/dds/dds_test_peer_main.cpp)
  target_link_libraries(dds_test_peer srd_dds)
  catkin_add_gtest(dds_discovery_tests test/dds/test_second_participant.cpp
    test/dds_front/ros2_peer.cpp)
  target_link_libraries(dds_discovery_tests srd_dds gtest_main)
  target_compile_definitions(dds_discovery_tests PRIVATE
    SRD_DDS_TEST_PEER="$<TARGET_FILE:dds_test_peer>")
  add_dependencies(dds_discovery_tests dds_test_peer)
  # The same node seen by another DDS implementation, Debian's Fast DDS, when it is installed.
  find_package(fastrtps QUIET)
  if(fastrtps_FOUND)
    catkin_add_gtest(dds_fast_dds_tests test/dds/test_fast_dds_peer.cpp)
    target_link_libraries(dds_fast_dds_tests fastrtps gtest_main)
    target_compile_definitions(dds_fast_dds_tests PRIVATE
      SRD_DDS_TEST_PEER="$<TARGET_FILE:dds_test_peer>")
    add_dependencies(dds_fast_dds_tests dds_test_peer)
  else()
    message(STATUS
      "${PROJECT_NAME}: Fast DDS not found (libfastrtps-dev): dds_fast_dds_tests left out")
  endif()
endif()

# Sources of the ROS-free core library, shared by the catkin build and the standalone fuzz build.
# Paths are relative to the repository root (SRD_ROOT); the devices' own sources come from their
# folders (cmake/devices.cmake), the device registry is generated (SRD_CORE_GENERATED_SOURCES).
include(${SRD_ROOT}/cmake/devices.cmake)
set(SRD_CORE_SOURCES
  src/protocol/decode_result.cpp
  src/protocol/stream_framer.cpp
  src/kinematics/diff_drive.cpp
  src/kinematics/odometry.cpp
  src/kinematics/heading_fusion.cpp
  src/transport/read_waiter.cpp
  src/transport/serial_port.cpp
  src/transport/tcp_stream.cpp
  src/transport/termios2_baud.cpp
  src/transport/recorded_stream.cpp
  src/core/serial_link.cpp
  src/core/loop_clock.cpp
  src/core/loop_wake.cpp
  src/core/realtime.cpp
  src/core/scheduler_slice.cpp
  src/core/device_module.cpp
  src/params/device_sections.cpp
  src/params/param_table.cpp
  src/params/driver_params.cpp
  src/trajectory/spline.cpp
  src/trajectory/command.cpp
  src/trajectory/command_start.cpp
  src/trajectory/tolerances.cpp
  src/trajectory/bus_joint.cpp
  src/trajectory/joint_groups.cpp
  src/trajectory/goal.cpp
  src/trajectory/message_time.cpp
  src/trajectory/executor.cpp
  src/core/e_stop.cpp
  src/core/motion_gate.cpp
  src/core/status_report.cpp
  src/core/event_rate.cpp
  src/core/link_status.cpp
  src/core/e_stop_status.cpp
  src/core/input_refusals.cpp
  src/core/guarded_call.cpp
  src/core/driver_core.cpp
  src/core/log.cpp
  src/core/port_log.cpp
  src/core/wire_capture_status.cpp
  src/core/capture_queue.cpp
  src/core/params_in_force.cpp
  src/core/stop_signals.cpp
  src/core/recording_replay.cpp
  src/core/wall_stamps.cpp
)

srd_device_sources(core srd_device_core_sources)
list(APPEND SRD_CORE_SOURCES ${srd_device_core_sources})
srd_write_registry("${PROJECT_BINARY_DIR}/srd_generated/registered_devices.cpp"
  "serial_robot_driver/core/device_module.h" "serial_robot_driver::core::DeviceModule" kModule
  "serial_robot_driver::core::registeredDevices" "")
set(SRD_CORE_GENERATED_SOURCES "${PROJECT_BINARY_DIR}/srd_generated/registered_devices.cpp")

# The simulated robot (ROS-free as well) and the pseudo-terminals it plays the robot on: robot_sim,
# the tests and the benchmarks use them; the driver never does.
set(SRD_SIM_SOURCES
  src/sim/pseudo_terminal.cpp
  src/sim/robot_sim.cpp
  src/sim/robot_sim_line.cpp
  src/sim/robot_sim_plug.cpp
  src/sim/robot_sim_tcp.cpp
  src/sim/robot_sim_hosted.cpp
  src/sim/command_line.cpp
  src/sim/sim_stats.cpp
  src/sim/sim_device_module.cpp
  src/sim/sim_option_builders.cpp
)
srd_device_sources(sim srd_device_sim_sources)
list(APPEND SRD_SIM_SOURCES ${srd_device_sim_sources})
# The simulator parts robot_sim can host (sim/sim_device_module.h): every device with a sim/ folder.
srd_write_registry("${PROJECT_BINARY_DIR}/srd_generated/registered_sim_devices.cpp"
  "serial_robot_driver/sim/sim_device_module.h" "serial_robot_driver::sim::SimDeviceModule"
  kSimModule "serial_robot_driver::sim::registeredSimDevices" sim)
list(APPEND SRD_SIM_SOURCES "${PROJECT_BINARY_DIR}/srd_generated/registered_sim_devices.cpp")

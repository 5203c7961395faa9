# Sources of the ROS-free core library, shared by the catkin build and the standalone fuzz build.
set(SRD_CORE_SOURCES
  src/protocol/decode_result.cpp
  src/protocol/base_codec.cpp
  src/protocol/body_codec.cpp
  src/protocol/servo_params.cpp
  src/protocol/servo_bus_codec.cpp
  src/protocol/stream_framer.cpp
  src/kinematics/diff_drive.cpp
  src/transport/serial_port.cpp
  src/transport/pseudo_terminal.cpp
  src/device/serial_link.cpp
  src/device/base_controller.cpp
  src/device/body_controller.cpp
  src/device/servo_bus_client.cpp
)

# The simulated robot (ROS-free as well): robot_sim and the tests drive it.
set(SRD_SIM_SOURCES
  src/sim/base_sim.cpp
  src/sim/body_sim.cpp
  src/sim/servo_bus_sim.cpp
  src/sim/robot_sim.cpp
  src/sim/command_line.cpp
  src/sim/sim_stats.cpp
)

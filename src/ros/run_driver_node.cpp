#include "serial_robot_driver/ros/run_driver_node.h"

#include <pthread.h>

#include <csignal>
#include <ctime>
#include <string>
#include <vector>

#include "serial_robot_driver/ros/driver_node.h"
#include "serial_robot_driver/ros/queue_spinner.h"

namespace serial_robot_driver::ros_layer {

namespace {
/// Waits for SIGINT/SIGTERM (blocked in every thread, taken here synchronously) or for roscpp to
/// shut down (rosnode kill), checking the latter twice a second.
void waitForStopRequest(const sigset_t& stop_signals) {
  const timespec half_second{0, 500000000};
  while (ros::ok()) {
    if (sigtimedwait(&stop_signals, nullptr, &half_second) > 0) return;
  }
}
}  // namespace

int runDriverNode(int argc, char** argv, const StreamFactoryMaker& make_stream_factory) {
  // We take SIGINT ourselves: roscpp's handler would tear the node down before the zero-speed frame
  // is out. Blocking the signals before any thread starts makes every thread inherit the mask.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  ros::init(argc, argv, "driver_node", ros::init_options::NoSigintHandler);

  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  device::SerialLink::StreamFactory stream_factory;
  DriverParams params;
  try {
    if (make_stream_factory) stream_factory = make_stream_factory(private_nh);
    std::vector<std::string> unknown;
    params = loadParams(private_nh, &unknown);
    for (const auto& key : unknown) {
      ROS_WARN("unknown parameter ~%s is ignored (a typo?)", key.c_str());
    }
    params.validate();
  } catch (const ParameterError& e) {
    ROS_FATAL("%s", e.what());
    ros::shutdown();
    return 2;
  }

  DriverNode node(nh, private_nh, params, stream_factory);
  node.start();
  // Global queue: cmd_vel, joint_commands, base services and the diagnostics timer. None of them
  // waits on the wire (servo/* services have their own queue), so one thread keeps up. Unlike
  // ros::AsyncSpinner it does not wake every 100 ms while the node is idle.
  QueueSpinner spinner(ros::getGlobalCallbackQueue(), 1);
  spinner.start();
  waitForStopRequest(stop_signals);
  ROS_INFO("shutting down: stopping the wheels");
  node.shutdown();
  spinner.stop();
  ros::shutdown();
  return 0;
}

}  // namespace serial_robot_driver::ros_layer

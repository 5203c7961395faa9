// polling_driver_node: driver_node whose ports are read once per ~read_poll_interval (s) instead
// of as bytes arrive, built from the same DriverNode. driver_bench runs it to show what the
// event-driven reader buys; it is never installed for a robot.
#include <ros/ros.h>

#include <memory>

#include "polling_stream.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/run_driver_node.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace {

serial_robot_driver::core::SerialLink::StreamFactory pollingStreams(ros::NodeHandle& private_nh) {
  using namespace serial_robot_driver;
  double interval = 0.0;
  private_nh.getParam("read_poll_interval", interval);
  private_nh.deleteParam("read_poll_interval");  // not a driver parameter: no "unknown" warning
  if (!(interval > 0.0)) {
    throw ros_layer::ParameterError("read_poll_interval", "must be > 0 s for the polling node");
  }
  return [interval](
             const core::SerialLinkOptions& options) -> std::unique_ptr<transport::ByteStream> {
    return std::make_unique<bench::PollingStream>(
        std::make_unique<transport::SerialPort>(
            transport::SerialPortOptions{options.path, options.baud}),
        interval);
  };
}

}  // namespace

int main(int argc, char** argv) {
  return serial_robot_driver::ros_layer::runDriverNode(argc, argv, pollingStreams);
}

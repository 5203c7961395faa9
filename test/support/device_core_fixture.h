// One real device in a core::DriverCore on an in-memory port, the other registered devices
// disabled: how a device's core tests reach it as every front end does (built by its module's
// make_device, its outputs to two listeners standing for two front ends).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/params/driver_params.h"
#include "support/log_capture.h"
#include "support/memory_stream.h"

namespace test_support {

/// `DeviceT` is the class the module called `device_name` makes; `Listener` records its outputs.
template <typename DeviceT, typename Listener>
class DeviceCoreFixture : public ::testing::Test {
 protected:
  explicit DeviceCoreFixture(std::string device_name) : device_name_(std::move(device_name)) {
    params_.port = "memory";
    for (const serial_robot_driver::core::DeviceModule* module :
         serial_robot_driver::core::registeredDevices()) {
      if (module->name != device_name_) params_.portParams(*module).enabled = false;
    }
  }
  ~DeviceCoreFixture() override {
    if (core_) core_->shutdown();
  }

  DeviceT& makeDevice() {
    core_ = std::make_unique<serial_robot_driver::core::DriverCore>(params_, memoryStreams(wire_));
    // Built by the device's module (make_device): a DeviceT.
    return static_cast<DeviceT&>(*core_->device(device_name_));
  }
  void start() {
    core_->start();
    ASSERT_TRUE(core_->ports().at("memory")->waitConnected(std::chrono::seconds(5)));
  }

  const std::string device_name_;
  LogCapture logs_;  // outlives the core's threads, which may log
  MemoryWire wire_;  // outlives the core's link
  Listener first_;   // the front ends' outputs outlive the core's threads
  Listener second_;
  serial_robot_driver::params::DriverParams params_;
  std::unique_ptr<serial_robot_driver::core::DriverCore> core_;
};

}  // namespace test_support

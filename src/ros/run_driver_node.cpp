#include "serial_robot_driver/ros/run_driver_node.h"

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/core/stop_signals.h"
#include "serial_robot_driver/dds_front/ros2_graph.h"
#include "serial_robot_driver/ros/bag_replay.h"
#include "serial_robot_driver/ros/driver_node.h"
#include "serial_robot_driver/ros/queue_spinner.h"

namespace serial_robot_driver::ros_layer {

namespace {
/// How often the wait for a stop checks whether roscpp shut down (rosnode kill): twice a second,
/// 20 times while replaying, whose end is worth noticing soon.
constexpr std::chrono::milliseconds kStopCheckPeriod{500};
constexpr std::chrono::milliseconds kReplayCheckPeriod{50};
}  // namespace

DriverParams loadCheckedParams(const ros::NodeHandle& private_nh) {
  std::vector<std::string> unknown;
  DriverParams params = loadParams(private_nh, &unknown);
  for (const auto& key : unknown) {
    ROS_WARN("unknown parameter ~%s is ignored (a typo?)", key.c_str());
  }
  params.validate();
  dds_front::requireRos2Support(params);
  return params;
}

namespace {

/// A replay is the same node on recorded ports: only the streams behind the links differ. Points
/// `stream_factory` at the recording and paces `params` by it; throws ReplayError.
std::unique_ptr<BagReplay> openReplay(DriverParams& params,
                                      core::SerialLink::StreamFactory& stream_factory) {
  auto replay = std::make_unique<BagReplay>(params);
  replay->standIn(params, stream_factory);
  ROS_INFO("replaying %s from %s at %s", replay->recording().topic.c_str(),
           params.replay_bag.c_str(), core::replayPaceText(params.replay_rate).c_str());
  return replay;
}

/// Starts `node` (and the replay's clock) and serves it until a stop is asked for or the replay
/// ends, then shuts it down.
void runUntilStopped(DriverNode& node, BagReplay* replay, const core::StopSignals& stop_signals,
                     int realtime_priority) {
  if (replay) {
    std::this_thread::sleep_for(core::kReplaySettle);
    replay->startClock();
  }
  node.start();
  // Global queue: cmd_vel, joint_commands, base services and the diagnostics timer. None of them
  // waits on the wire (servo/* services have their own queue), so one thread keeps up. Unlike
  // ros::AsyncSpinner it does not wake every 100 ms while the node is idle. On the way of a command
  // to the wire, so real-time too, but below the frame threads like roscpp's poll thread that
  // hands it the commands (core/realtime.h): its diagnostics and services never hold up a frame.
  QueueSpinner spinner(ros::getGlobalCallbackQueue(), 1, core::supportPriority(realtime_priority));
  spinner.start();
  const bool replay_done =
      replay ? stop_signals.wait(
                   kReplayCheckPeriod, [] { return ros::ok(); }, [&] { return replay->finished(); })
             : stop_signals.wait(kStopCheckPeriod, [] { return ros::ok(); });
  if (replay_done) {
    node.updateDiagnostics();  // the counters at the end of the recording
    ROS_INFO("%s", replay->summary().c_str());
    std::this_thread::sleep_for(core::kReplayLinger);
  }
  ROS_INFO("shutting down: stopping the wheels and the bus servos");
  node.shutdown();
  spinner.stop();
}

/// How the main thread is scheduled, before roscpp starts its threads (with the first NodeHandle;
/// ros::param needs none), so that every thread of the process inherits it, roscpp's too (the poll
/// thread that carries messages to and from the sockets, its timers) and the path of a frame or a
/// command is scheduled as a whole:
///  - ~scheduler_slice_us: the fair scheduler's short slice (core/scheduler_slice.h);
///  - ~realtime_priority: its lower level (core::supportPriority), so the whole path runs ahead of
///    normal processes, and the port readers and the base loop (which take the priority itself)
///    preempt all of it.
/// Checked and logged once by DriverCore::start(); a value validate() refuses is not applied here.
void scheduleThreadsBeforeRoscpp() {
  int slice_us = DriverParams{}.scheduler_slice_us;
  ros::param::get("~scheduler_slice_us", slice_us);
  if (slice_us >= core::kMinSchedulerSliceUs && slice_us <= core::kMaxSchedulerSliceUs) {
    core::requestSchedulerSlice(slice_us);  // first: a SCHED_FIFO thread takes none
  }
  int priority = 0;
  if (!ros::param::get("~realtime_priority", priority)) return;
  if (priority > 0 && priority <= core::kMaxRealtimePriority) {
    core::enterRealtime(core::supportPriority(priority));
  }
}

}  // namespace

int runDriverNode(int argc, char** argv, const StreamFactoryMaker& make_stream_factory) {
  // We take SIGINT ourselves: roscpp's handler would tear the node down before the zero-speed frame
  // is out. Blocking the signals before any thread starts makes every thread inherit the mask.
  const core::StopSignals stop_signals;
  ros::init(argc, argv, "driver_node", ros::init_options::NoSigintHandler);
  scheduleThreadsBeforeRoscpp();

  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  core::SerialLink::StreamFactory stream_factory;
  DriverParams params;
  std::unique_ptr<BagReplay> replay;
  try {
    if (make_stream_factory) stream_factory = make_stream_factory(private_nh);
    params = loadCheckedParams(private_nh);
    if (!params.replay_bag.empty()) replay = openReplay(params, stream_factory);
  } catch (const ParameterError& e) {
    ROS_FATAL("%s", e.what());
    ros::shutdown();
    return 2;
  } catch (const ReplayError& e) {
    ROS_FATAL("%s", e.what());
    ros::shutdown();
    return 1;
  }
  DriverNode node(nh, private_nh, params, stream_factory);
  runUntilStopped(node, replay.get(), stop_signals, params.realtime_priority);
  ros::shutdown();
  return 0;
}

}  // namespace serial_robot_driver::ros_layer

// A second driver_node in namespace "sim" closed-loop with robot_sim (body_node.test), and
// launch/record.launch recording that namespace; and the main() of the test_body_node target.
#include <gtest/gtest.h>

#include "serial_robot_driver/devices/body/body_codec.h"
#include "support/body_node_fixture.h"

namespace {

using namespace body_node_test;  // NOLINT: the shared fixture

TEST(BodyNodeSim, JointCommandsMoveTheSimulatedServos) {
  ros::NodeHandle nh(g_sim_ns);
  Inbox<JointState> joints;
  Inbox<Imu> imu;
  ros::Subscriber joints_sub = subscribe(nh, "joint_states", &joints);
  ros::Subscriber imu_sub = subscribe(nh, "imu/data", &imu);
  ros::Publisher commands = nh.advertise<JointState>("joint_commands", 10);
  ASSERT_TRUE(joints.waitFor([](const JointState&) { return true; }, 60.0))
      << "no joint_states from the driver attached to robot_sim";
  ASSERT_TRUE(waitFor([&] { return commands.getNumSubscribers() > 0; }, 30.0));

  const double hip = 0.5, knee = -0.25;
  commands.publish(command({"hip", "knee"}, {hip, knee}));
  const auto reached = [&](const JointState& m) {
    return m.position.size() == 2 && std::abs(m.position[0] - hip) <= kRadPerTick &&
           std::abs(m.position[1] - knee) <= kRadPerTick;
  };
  EXPECT_TRUE(joints.waitFor(reached, 30.0)) << "the simulated servos never reached the targets";

  // The simulator's IMU sees 1 g on z at 16 g full scale: the default scales give 9.81 m/s^2.
  const auto any_imu = imu.waitFor([](const Imu&) { return true; }, 10.0);
  ASSERT_TRUE(any_imu);
  const std::vector<Imu> received = imu.snapshot();
  ASSERT_FALSE(received.empty());
  EXPECT_NEAR(received.back().linear_acceleration.z, 9.80665, 0.05);
}

bool recorderSubscribed(const std::string& topic) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) return false;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i) {
    if (static_cast<std::string>(subscribers[i][0]) != topic) continue;
    for (int j = 0; j < subscribers[i][1].size(); ++j) {
      if (static_cast<std::string>(subscribers[i][1][j]).find("record") != std::string::npos) {
        return true;
      }
    }
  }
  return false;
}

std::string runAndCapture(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  pclose(pipe);
  return output;
}

TEST(BodyNodeSim, RecordLaunchRecordsEveryTopic) {
  char dir_template[] = "/tmp/srd_body_record_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  const std::string ns = g_sim_ns;

  // roslaunch record.launch against this test's master, as a child we stop with SIGINT (Ctrl-C).
  test_support::ChildProcess launch(
      "roslaunch", {"serial_robot_driver", "record.launch", "bag:=" + dir + "/test", "ns:=" + ns},
      {"ROS_MASTER_URI=" + ros::master::getURI()});
  ASSERT_TRUE(launch.started()) << "could not start roslaunch";

  const std::string prefix = "/" + ns + "/";
  ros::NodeHandle nh(ns);
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ros::Publisher joint_commands = nh.advertise<JointState>("joint_commands", 10);
  const bool subscribed = waitFor(
      [&] {
        // Each input topic has the driver and the recorder as subscribers.
        return recorderSubscribed(prefix + "telemetry") && cmd_vel.getNumSubscribers() >= 2 &&
               joint_commands.getNumSubscribers() >= 2;
      },
      60.0);
  if (subscribed) {
    cmd_vel.publish(geometry_msgs::Twist());
    joint_commands.publish(command({"hip"}, {0.1}));
    // A few seconds: diagnostics and battery come at 1 Hz.
    ros::WallDuration(3.5).sleep();
  }
  launch.signal(SIGINT);
  const bool exited = launch.waitExit(60.0).has_value();  // if not, the destructor kills it
  ASSERT_TRUE(subscribed) << "rosbag record never subscribed; roslaunch said:\n" << launch.output();
  ASSERT_TRUE(exited) << "roslaunch did not stop on SIGINT";

  glob_t found;
  const std::string pattern = dir + "/test_*.bag";
  ASSERT_EQ(glob(pattern.c_str(), 0, nullptr, &found), 0) << "no bag matching " << pattern;
  ASSERT_EQ(found.gl_pathc, 1u);
  const std::string bag = found.gl_pathv[0];
  globfree(&found);
  const std::string info = runAndCapture("rosbag info " + bag + " 2>&1");
  for (const std::string& topic :
       {prefix + "joint_states", prefix + "imu/data", prefix + "foot_pressure",
        prefix + "telemetry", prefix + "wheel_command", prefix + "battery", prefix + "cmd_vel",
        prefix + "joint_commands", std::string("/diagnostics")}) {
    EXPECT_NE(info.find(topic + " "), std::string::npos) << topic << " missing from\n" << info;
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);  // kept for a look when something failed
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_body_node");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  std::string port = "/tmp/srd_test_body";
  private_nh.param("port", port, port);
  private_nh.param("sim_ns", g_sim_ns, std::string("sim"));

  Board board;
  // The pty first: the node keeps retrying its port until the symlink exists.
  serial_robot_driver::protocol::FramerConfig framer;
  framer.accept(serial_robot_driver::devices::body::kSyncWriteFrames);
  board.device = std::make_unique<test_support::FakeDevice>(port, framer);
  board.device->plug();
  board.subscribers.push_back(subscribe(nh, "joint_states", &board.joints));
  board.subscribers.push_back(subscribe(nh, "imu/data", &board.imu));
  board.subscribers.push_back(subscribe(nh, "foot_pressure", &board.foot));
  board.subscribers.push_back(subscribe(nh, "telemetry", &board.telemetry));
  board.joint_commands = nh.advertise<JointState>("joint_commands", 10);
  g_board = &board;

  const int result = RUN_ALL_TESTS();
  g_board = nullptr;
  board.device->unplug();
  return result;
}

// dds_test_peer DOMAIN: a ROS 2 node made with the DDS wrappers, for test_second_participant.cpp
// to discover from another process: node "dds_test_peer" in namespace "/dds_test", unicast peer
// 127.0.0.1; publishes joint_states (names "left", "right", positions 0.25 and -1.5, stamp 7 s
// 8 ns, frame "base_link") every 100 ms, subscribes to e_stop. Runs until its stdin closes.
#include <poll.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds/subscription.h"

namespace dds = serial_robot_driver::dds;

namespace {

bool stdinClosed(int timeout_ms) {
  pollfd input{STDIN_FILENO, POLLIN, 0};
  if (poll(&input, 1, timeout_ms) <= 0) return false;
  char byte;
  return read(STDIN_FILENO, &byte, 1) <= 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dds_test_peer DOMAIN\n");
    return 2;
  }
  dds::NodeOptions options;
  options.name = "dds_test_peer";
  options.node_namespace = "/dds_test";
  options.domain_id = std::atoi(argv[1]);
  options.peers = {"127.0.0.1"};
  dds::Participant participant(options);
  dds::Publisher<sensor_msgs_msg_dds__JointState_> joint_states(participant, "joint_states");
  dds::Subscription<std_msgs_msg_dds__Bool_> e_stop(participant, "e_stop",
                                                    [](const std_msgs_msg_dds__Bool_&) {});
  const std::string frame = "base_link";
  std::vector<std::string> names{"left", "right"};
  std::vector<double> positions{0.25, -1.5};
  dds::StringPointers name_pointers(names);
  sensor_msgs_msg_dds__JointState_ state{};
  state.header.stamp = {7, 8};
  dds::lend(state.header.frame_id, frame);
  name_pointers.lendTo(state.name);
  dds::lend(state.position, positions);
  while (!stdinClosed(100)) joint_states.publish(state);
  return 0;
}

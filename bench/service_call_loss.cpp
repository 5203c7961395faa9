// service_call_loss: how often roscpp loses a service call on a busy machine, whichever server.
//
//   service_call_loss --server              advertises /call_loss (std_srvs/Trigger, answered at
//                                           once by two spinner threads, as driver_node's servo
//                                           services are) until shut down
//   service_call_loss --client MODE [N]     calls /call_loss N times (2000) and prints one line:
//                                           "MODE: F of N calls lost"
//
// MODE is how the client connects: `new` a new connection per call (ros::service::call, what
// rosservice does), `fresh` a persistent client made for each call (test_support::callService),
// `kept` one persistent client for all the calls (made again after a loss). A lost call is one
// whose call() returned false: this server always answers true. bench/service_call_loss.sh runs a
// server, CPU hogs and four clients of each mode side by side. Numbers only: nothing is asserted.
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

const char* const kService = "/call_loss";

int runServer(int argc, char** argv) {
  ros::init(argc, argv, "call_loss_server");
  ros::NodeHandle nh;
  ros::CallbackQueue queue;  // its own queue and threads, like driver_node's servo services
  nh.setCallbackQueue(&queue);
  const boost::function<bool(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&)> answer =
      [](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
        res.success = true;
        res.message = "answered";
        return true;
      };
  const ros::ServiceServer server = nh.advertiseService(kService, answer);
  ros::AsyncSpinner spinner(2, &queue);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}

bool callOnce(const std::string& mode, ros::NodeHandle& nh, ros::ServiceClient& kept) {
  std_srvs::Trigger srv;
  if (mode == "new") return ros::service::call(kService, srv);
  if (mode == "fresh") return nh.serviceClient<std_srvs::Trigger>(kService, true).call(srv);
  if (!kept.isValid()) kept = nh.serviceClient<std_srvs::Trigger>(kService, true);
  return kept.call(srv);
}

int runClient(int argc, char** argv, const std::string& mode, int calls) {
  ros::init(argc, argv, "call_loss_client", ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  if (!ros::service::waitForService(kService, ros::Duration(20))) {
    std::fprintf(stderr, "%s: no %s\n", mode.c_str(), kService);
    return 1;
  }
  ros::ServiceClient kept;
  int lost = 0;
  for (int i = 0; i < calls; ++i) {
    if (!callOnce(mode, nh, kept)) ++lost;
  }
  std::printf("%s: %d of %d calls lost\n", mode.c_str(), lost, calls);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string role = argc > 1 ? argv[1] : "";
  if (role == "--server") return runServer(argc, argv);
  const std::string mode = argc > 2 ? argv[2] : "";
  if (role == "--client" && (mode == "new" || mode == "fresh" || mode == "kept")) {
    const int calls = argc > 3 ? std::atoi(argv[3]) : 2000;
    return runClient(argc, argv, mode, calls > 0 ? calls : 2000);
  }
  std::fprintf(stderr, "usage: %s --server | --client new|fresh|kept [calls]\n", argv[0]);
  return 2;
}

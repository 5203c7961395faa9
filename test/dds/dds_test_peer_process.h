#pragma once
// dds_test_peer (dds_test_peer_main.cpp) as a child process: started on a domain, ended by closing
// its stdin (killed, only this child, if it does not end).

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

#include "dds_test_support.h"

extern char** environ;

namespace dds_test {

class PeerProcess {
 public:
  ~PeerProcess() { stop(); }

  /// False when the child cannot be started.
  bool start(int domain_id) {
    int input[2];
    if (pipe(input) != 0) return false;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, input[0], STDIN_FILENO);
    posix_spawn_file_actions_addclose(&actions, input[1]);
    const std::string domain = std::to_string(domain_id);
    char* const argv[] = {const_cast<char*>(SRD_DDS_TEST_PEER), const_cast<char*>(domain.c_str()),
                          nullptr};
    const bool started =
        posix_spawn(&pid_, SRD_DDS_TEST_PEER, &actions, nullptr, argv, environ) == 0;
    posix_spawn_file_actions_destroy(&actions);
    close(input[0]);
    stdin_ = input[1];
    if (!started) pid_ = 0;
    return started;
  }

  void stop() {
    if (pid_ <= 0) return;
    close(stdin_);
    int status = 0;
    if (!waitFor([&] { return waitpid(pid_, &status, WNOHANG) == pid_; })) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
    }
    pid_ = 0;
  }

 private:
  pid_t pid_ = 0;
  int stdin_ = -1;
};

}  // namespace dds_test

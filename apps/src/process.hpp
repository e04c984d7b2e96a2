// Child processes for the programs that launch agents.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <filesystem>
#include <string>
#include <vector>

namespace simsoccer::apps {

// A child process, killed (SIGTERM, then SIGKILL) when this goes.
class ChildProcess {
 public:
  explicit ChildProcess(std::vector<std::string> args);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  bool started() const { return pid_ > 0; }
  // False once the process has exited (reaped; exitStatus() then tells how).
  bool running();
  int exitStatus() const { return exit_status_; }  // exit code, or 128 + signal
  void stop();

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
};

// The simsoccer-agent program beside the running executable.
std::filesystem::path agentProgram();

// Bytes sent on the loopback interface so far (/proc/net/dev), or -1.
long long loopbackBytes();

}  // namespace simsoccer::apps

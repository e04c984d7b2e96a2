// Child processes for the programs that launch agents.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace simsoccer::match {

// A child process, killed (SIGTERM, then SIGKILL) when this goes.
class ChildProcess {
 public:
  // `environment`: NAME=VALUE entries set for the child on top of this
  // process's environment.
  explicit ChildProcess(std::vector<std::string> args, std::vector<std::string> environment = {});
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  bool started() const { return pid_ > 0; }
  int spawnError() const { return spawn_error_; }  // errno of a failed start, else 0
  pid_t pid() const { return pid_; }
  // False once the process has exited (reaped; exitStatus() then tells how).
  bool running();
  int exitStatus() const { return exit_status_; }  // exit code, or 128 + signal
  void stop();

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
  int spawn_error_ = 0;
};

// The simsoccer-agent program beside the running executable.
std::filesystem::path agentProgram();

// One soccer agent process as a match or bench scaling starts it. It waits
// for the referee's GameState (published before the agents start) before it
// claims its robot, so its first answers already know the game's state.
struct SoccerAgentOptions {
  int team = 0, player = 0, domain = 0;
  std::string role = "auto";
  std::filesystem::path field;
  std::filesystem::path robot;       // the robot model's file; empty: the agent's default (Nao)
  std::filesystem::path config;      // empty: the agent's default
  std::filesystem::path motions;     // the motions and gaits folder; empty: the agent's default
  std::filesystem::path dds_config;  // Cyclone configuration; empty: the agent's default
  std::optional<int> team_number;    // GameController team number
  std::optional<uint64_t> seed;      // the agent's own random numbers
  bool get_up = true;                // after a fall
  double game_state_wait = 10.0;     // s
  double gone_after = 5.0;  // s without a frame before the agent takes the simulator for gone
};
std::vector<std::string> soccerAgentCommand(const SoccerAgentOptions& o);

// Bytes sent on the loopback interface so far (/proc/net/dev), or -1.
long long loopbackBytes();
// Packets sent on the loopback interface so far (/proc/net/dev), or -1.
long long loopbackPackets();
// CPU time (user + system) the threads of a process have used so far, in
// seconds (/proc/PID/task/*/schedstat), or -1 when it cannot be read.
double processCpuSeconds(pid_t pid);
// CPU time this process and `children` have used so far, in seconds, or -1
// when one cannot be read.
double cpuSecondsWithChildren(const std::vector<std::unique_ptr<ChildProcess>>& children);
// CPU time the calling thread has used so far, in seconds.
double threadCpuSeconds();

}  // namespace simsoccer::match

// A simsoccer-agent process for the tests that start agents themselves.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"

extern char** environ;

namespace simsoccer::test {

// A simsoccer-agent process, killed (SIGKILL) when this goes.
class AgentProcess {
 public:
  // `environment`: NAME=VALUE entries added to this process's environment.
  // `dds_config`: its Cyclone configuration (empty: configs/dds/loopback.xml).
  AgentProcess(uint32_t domain, int team, int player, std::vector<std::string> extra = {},
               std::vector<std::string> environment = {},
               const std::filesystem::path& dds_config = {}) {
    std::vector<std::string> args = {SIMSOCCER_AGENT_BIN,
                                     "--team",
                                     std::to_string(team),
                                     "--player",
                                     std::to_string(player),
                                     "--domain",
                                     std::to_string(domain),
                                     "--dds-config",
                                     (dds_config.empty() ? sourceDir() / "configs/dds/loopback.xml"
                                                         : dds_config)
                                         .string()};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<char*> envp;
    for (char** e = environ; *e; ++e) envp.push_back(*e);
    for (auto& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
  }
  ~AgentProcess() { kill(); }
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  // Exit status once it ended by itself (waits up to `seconds`, 0: looks
  // once), or -1.
  int exitStatus(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int>(seconds * 1000));
    for (;;) {
      int status = 0;
      if (pid_ > 0 && waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        return exit_status_;
      }
      if (pid_ <= 0) return exit_status_;
      if (std::chrono::steady_clock::now() >= end) return -1;
      usleep(10000);
    }
  }
  bool running() const { return pid_ > 0; }

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
};

}  // namespace simsoccer::test

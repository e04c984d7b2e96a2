// A child process for the tests (agents, SDK clients): started with extra
// environment entries and optionally its standard output in a file, killed
// (SIGKILL) when this goes.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

extern char** environ;

namespace simsoccer::test {

class ChildProcess {
 public:
  // `environment`: NAME=VALUE entries added to this process's environment;
  // `stdout_file`: where its standard output goes (empty: this process's).
  explicit ChildProcess(std::vector<std::string> args, std::vector<std::string> environment = {},
                        const std::filesystem::path& stdout_file = {}) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<char*> envp;
    for (char** e = environ; *e; ++e) envp.push_back(*e);
    for (auto& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (!stdout_file.empty())
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_file.c_str(),
                                       O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~ChildProcess() { kill(); }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
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
    const auto end = std::chrono::steady_clock::now() +
                     std::chrono::milliseconds(static_cast<int>(seconds * 1000));
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
  pid_t pid() const { return pid_; }
  bool started() const { return pid_ > 0 || exit_status_ >= 0; }

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
};

}  // namespace simsoccer::test

#include "simsoccer/lola/field_network.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <stdexcept>

extern char** environ;

namespace simsoccer::lola {

std::string FieldNetwork::robotAddress(int team_number, int player) const {
  if (team_number < 1 || team_number > 254 || player < 1 || player > 20)
    throw std::invalid_argument("field network: team " + std::to_string(team_number) +
                                " player " + std::to_string(player) +
                                " has no address (team 1..254, player 1..20)");
  return prefix + "." + std::to_string(team_number) + "." + std::to_string(player);
}

std::string FieldNetwork::namespaceName(int team_number, int player) const {
  return bridge + "-" + std::to_string(team_number) + "-" + std::to_string(player);
}

std::string runTool(const std::vector<std::string>& args) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  std::string out;
  char buffer[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;)
    out.append(buffer, static_cast<size_t>(n));
  ::close(pipe_fds[0]);
  int status = -1;
  if (spawned == 0)
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  if (spawned != 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string line;
    for (const std::string& a : args) line += (line.empty() ? "" : " ") + a;
    throw std::runtime_error("`" + line + "` failed" + (spawned ? " to start" : "") +
                             (out.empty() ? "" : ": " + out));
  }
  return out;
}

namespace {
void quietly(const std::vector<std::string>& args) {
  try {
    runTool(args);
  } catch (const std::runtime_error&) {
    // Removing what is not there.
  }
}
}  // namespace

FieldBridge::FieldBridge(const FieldNetwork& net) : net_(net) {
  // Another run's bridge (or a killed run's) is not taken over.
  if (std::filesystem::exists("/sys/class/net/" + net_.bridge))
    throw std::runtime_error("field network: '" + net_.bridge +
                             "' exists: another run uses it (a killed run's: ip link del " +
                             net_.bridge + ")");
  runTool({"ip", "link", "add", net_.bridge, "type", "bridge"});
  try {
    runTool({"ip", "addr", "add", net_.hostAddress() + "/16", "broadcast", net_.broadcast(), "dev",
             net_.bridge});
    runTool({"ip", "link", "set", net_.bridge, "up"});
  } catch (...) {
    quietly({"ip", "link", "del", net_.bridge});
    throw;
  }
}

FieldBridge::~FieldBridge() {
  quietly({"ip", "link", "del", net_.bridge});
}

RobotNamespace::RobotNamespace(const FieldNetwork& net, int team_number, int player)
    : name_(net.namespaceName(team_number, player)),
      address_(net.robotAddress(team_number, player)),
      // Interface names have at most 15 characters.
      host_link_(net.link_prefix + std::to_string(team_number) + "p" + std::to_string(player)) {
  quietly({"ip", "netns", "del", name_});
  quietly({"ip", "link", "del", host_link_});
  runTool({"ip", "netns", "add", name_});
  try {
    runTool({"ip", "link", "add", host_link_, "type", "veth", "peer", "name", "eth0", "netns",
             name_});
    runTool({"ip", "link", "set", host_link_, "master", net.bridge, "up"});
    const auto in = [&](std::vector<std::string> args) {
      args.insert(args.begin(), {"ip", "-n", name_});
      runTool(args);
    };
    in({"link", "set", "lo", "up"});
    in({"addr", "add", address_ + "/16", "broadcast", net.broadcast(), "dev", "eth0"});
    in({"link", "set", "eth0", "up"});
    in({"route", "add", "default", "via", net.hostAddress()});
  } catch (...) {
    quietly({"ip", "link", "del", host_link_});
    quietly({"ip", "netns", "del", name_});
    throw;
  }
}

RobotNamespace::~RobotNamespace() {
  quietly({"ip", "link", "del", host_link_});
  quietly({"ip", "netns", "del", name_});
}

}  // namespace simsoccer::lola

#include "simsoccer/match/agent_process.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "simsoccer/sim/cores.hpp"

extern char** environ;

namespace simsoccer::match {

ChildProcess::ChildProcess(std::vector<std::string> args, std::vector<std::string> environment) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // This process's environment, less the names `environment` sets.
  std::vector<char*> envp;
  for (char** e = environ; *e; ++e) {
    const std::string_view entry(*e);
    const bool replaced = std::any_of(environment.begin(), environment.end(), [&](const auto& n) {
      const size_t eq = n.find('=');
      return entry.substr(0, entry.find('=')) == std::string_view(n).substr(0, eq);
    });
    if (!replaced) envp.push_back(*e);
  }
  for (auto& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  // During a pipelined run, off the CPU the periods run on (sim/cores.hpp).
  sim::CoreClaim::spawnOnOtherCpus([&] {
    // A program named without a '/' is looked up on PATH, as a shell would.
    spawn_error_ = posix_spawnp(&pid_, argv[0], nullptr, nullptr, argv.data(), envp.data());
    if (spawn_error_ != 0) pid_ = -1;
  });
}

ChildProcess::~ChildProcess() {
  stop();
}

bool ChildProcess::running() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
  exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  pid_ = -1;
  return false;
}

void ChildProcess::stop() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  for (int i = 0; i < 50; ++i) {
    if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
      pid_ = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

std::filesystem::path agentProgram() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path() / "simsoccer-agent";
}

std::vector<std::string> soccerAgentCommand(const SoccerAgentOptions& o) {
  std::vector<std::string> a{agentProgram().string(),
                             "--team",
                             std::to_string(o.team),
                             "--player",
                             std::to_string(o.player),
                             "--domain",
                             std::to_string(o.domain),
                             "--role",
                             o.role,
                             "--field",
                             o.field.string(),
                             "--game-state-wait",
                             std::to_string(o.game_state_wait)};
  if (o.team_number) a.insert(a.end(), {"--team-number", std::to_string(*o.team_number)});
  if (o.seed) a.insert(a.end(), {"--seed", std::to_string(*o.seed)});
  if (!o.robot.empty()) a.insert(a.end(), {"--robot", o.robot.string()});
  if (!o.config.empty()) a.insert(a.end(), {"--config", o.config.string()});
  if (!o.motions.empty()) a.insert(a.end(), {"--motions", o.motions.string()});
  if (!o.dds_config.empty()) a.insert(a.end(), {"--dds-config", o.dds_config.string()});
  if (!o.get_up) a.push_back("--no-get-up");
  if (o.gone_after != 5.0) a.insert(a.end(), {"--gone-after", std::to_string(o.gone_after)});
  return a;
}

namespace {
// Field `index` of the loopback line in /proc/net/dev (0: rx bytes, 1: rx
// packets, ..., 8: tx bytes, 9: tx packets), or -1.
long long loopbackField(int index) {
  std::ifstream f("/proc/net/dev");
  std::string line;
  while (std::getline(f, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    name.erase(0, name.find_first_not_of(' '));
    if (name != "lo") continue;
    std::istringstream in(line.substr(colon + 1));
    long long v = -1;
    for (int i = 0; i <= index; ++i)
      if (!(in >> v)) return -1;
    return v;
  }
  return -1;
}
}  // namespace

long long loopbackBytes() {
  return loopbackField(8);
}

long long loopbackPackets() {
  return loopbackField(9);
}

double processCpuSeconds(pid_t pid) {
  // Nanoseconds on the CPU per thread (/proc/PID/task/TID/schedstat, first
  // field): /proc/PID/stat counts in clock ticks (10 ms), too coarse for a
  // short run.
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  std::error_code ec;
  std::filesystem::directory_iterator it(tasks, ec);
  if (ec) return -1.0;
  double total = 0.0;
  bool any = false;
  for (; it != std::filesystem::directory_iterator(); it.increment(ec)) {
    if (ec) return -1.0;
    std::ifstream f(it->path() / "schedstat");
    long long ns = 0;
    if (!(f >> ns)) continue;  // a thread that just ended
    total += 1e-9 * static_cast<double>(ns);
    any = true;
  }
  return any && !ec ? total : -1.0;
}

double cpuSecondsWithChildren(const std::vector<std::unique_ptr<ChildProcess>>& children) {
  double total = processCpuSeconds(getpid());
  for (const auto& c : children) {
    const double s = processCpuSeconds(c->pid());
    if (s < 0 || total < 0) return -1.0;
    total += s;
  }
  return total;
}

double threadCpuSeconds() {
  timespec t{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) != 0) return -1.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace simsoccer::match

#include "simsoccer/sim/cores.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace simsoccer::sim {

namespace {

// The claim in force in this process (one at a time: a nested one claims nothing).
std::atomic<const CoreClaim*> g_active{nullptr};

std::vector<int> cpusOf(long tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(static_cast<pid_t>(tid), sizeof set, &set) != 0) return cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  return cpus;
}

void setCpus(long tid, const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int c : cpus) CPU_SET(c, &set);
  // A thread that ended meanwhile is no error.
  (void)sched_setaffinity(static_cast<pid_t>(tid), sizeof set, &set);
}

// Every thread of this process but `skip`.
template <class F>
void forOtherThreads(long skip, F&& f) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const long tid = std::strtol(entry.path().filename().c_str(), nullptr, 10);
    if (tid > 0 && tid != skip) f(tid);
  }
}

// Every thread of this process's children (the agents it started).
template <class F>
void forChildThreads(F&& f) {
  const std::string me = std::to_string(::getpid());
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string name = entry.path().filename();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // pid (comm) state ppid ...: the name may hold spaces and parentheses.
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 1));
    std::string state, ppid;
    rest >> state >> ppid;
    if (ppid != me) continue;
    for (const auto& task : std::filesystem::directory_iterator(entry.path() / "task", ec)) {
      const long tid = std::strtol(task.path().filename().c_str(), nullptr, 10);
      if (tid > 0) f(tid);
    }
  }
}

std::filesystem::path lockFile(int cpu) {
  const char* dir = std::getenv("XDG_RUNTIME_DIR");
  const std::filesystem::path base = dir && *dir ? dir : std::filesystem::temp_directory_path();
  return base / ("simsoccer-cpu" + std::to_string(cpu) + ".lock");
}

}  // namespace

CoreClaim::CoreClaim() {
  all_ = cpusOf(0);
  if (all_.size() < 2) return;
  const CoreClaim* none = nullptr;
  if (!g_active.compare_exchange_strong(none, this)) return;
  for (auto c = all_.rbegin(); c != all_.rend() && cpu_ < 0; ++c) {
    const int fd = ::open(lockFile(*c).c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      cpu_ = *c;
      lock_fd_ = fd;
    } else {
      ::close(fd);
    }
  }
  if (cpu_ < 0) {
    g_active = nullptr;
    return;
  }
  for (int c : all_)
    if (c != cpu_) others_.push_back(c);
  owner_tid_ = static_cast<long>(::gettid());
  setCpus(owner_tid_, {cpu_});
  placeOtherThreads();
}

CoreClaim::~CoreClaim() {
  if (cpu_ < 0) return;
  setCpus(owner_tid_, all_);
  forOtherThreads(owner_tid_, [&](long tid) { setCpus(tid, all_); });
  forChildThreads([&](long tid) { setCpus(tid, all_); });
  ::close(lock_fd_);  // releases the lock
  g_active = nullptr;
}

void CoreClaim::placeOtherThreads() const {
  if (cpu_ < 0) return;
  forOtherThreads(owner_tid_, [&](long tid) { setCpus(tid, others_); });
  forChildThreads([&](long tid) { setCpus(tid, others_); });
}

void CoreClaim::spawnOnOtherCpus(const std::function<void()>& spawn) {
  const CoreClaim* claim = g_active;
  if (!claim || !claim->held()) {
    spawn();
    return;
  }
  const std::vector<int> before = cpusOf(0);
  setCpus(0, claim->others_);
  spawn();
  setCpus(0, before);
}

}  // namespace simsoccer::sim

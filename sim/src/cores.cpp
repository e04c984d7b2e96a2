#include "simsoccer/sim/cores.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>

namespace simsoccer::sim {

namespace {

// The claim in force in this process (one at a time: a second claims
// nothing), read by spawnOnOtherCpus.
std::mutex g_mutex;
const CoreClaim* g_active = nullptr;

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
  if (cpus.empty()) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int c : cpus) CPU_SET(c, &set);
  // A thread that ended meanwhile is no error.
  (void)sched_setaffinity(static_cast<pid_t>(tid), sizeof set, &set);
}

// The thread ids in a /proc task folder. Threads and processes come and go
// while it is read: nothing here throws.
std::vector<long> tasksIn(const std::filesystem::path& folder) {
  std::vector<long> tids;
  std::error_code ec;
  std::filesystem::directory_iterator it(folder, ec);
  for (const std::filesystem::directory_iterator end; !ec && it != end; it.increment(ec)) {
    const long tid = std::strtol(it->path().filename().c_str(), nullptr, 10);
    if (tid > 0) tids.push_back(tid);
  }
  return tids;
}

// Every thread of this process but `skip`, and every thread of its child
// processes (the agents it started).
std::vector<long> otherThreads(long skip) {
  std::vector<long> tids = tasksIn("/proc/self/task");
  std::erase(tids, skip);
  const std::string me = std::to_string(::getpid());
  std::error_code ec;
  std::filesystem::directory_iterator it("/proc", ec);
  for (const std::filesystem::directory_iterator end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(it->path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // pid (comm) state ppid ...: the name may hold spaces and parentheses.
    const size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 1));
    std::string state, ppid;
    rest >> state >> ppid;
    if (ppid != me) continue;
    const std::vector<long> child = tasksIn(it->path() / "task");
    tids.insert(tids.end(), child.begin(), child.end());
  }
  return tids;
}

}  // namespace

std::filesystem::path CoreClaim::defaultLockFolder() {
  const char* dir = std::getenv("XDG_RUNTIME_DIR");
  if (dir && *dir) return dir;
  std::error_code ec;
  const std::filesystem::path tmp = std::filesystem::temp_directory_path(ec);
  return ec ? std::filesystem::path("/tmp") : tmp;
}

std::filesystem::path CoreClaim::lockFile(const std::filesystem::path& folder, int cpu) {
  return folder / ("simsoccer-cpu" + std::to_string(cpu) + ".lock");
}

CoreClaim::CoreClaim(const std::filesystem::path& lock_folder) {
  std::lock_guard lock(g_mutex);
  if (g_active) return;
  all_ = cpusOf(0);
  if (all_.size() < 2) return;
  const std::filesystem::path folder = lock_folder.empty() ? defaultLockFolder() : lock_folder;
  // The highest CPU no other run holds is ours; the others no run holds are
  // for the rest (a CPU another run holds is its period's).
  for (auto c = all_.rbegin(); c != all_.rend(); ++c) {
    const int fd = ::open(lockFile(folder, *c).c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      continue;
    }
    if (cpu_ < 0) {
      cpu_ = *c;
      lock_fd_ = fd;
    } else {
      others_.push_back(*c);
      ::close(fd);  // releases the probe's lock
    }
  }
  const auto claimNothing = [&] {
    if (lock_fd_ >= 0) ::close(lock_fd_);
    lock_fd_ = cpu_ = -1;
    others_.clear();
  };
  if (others_.empty()) {  // nothing left for the rest: leave placement to the scheduler
    claimNothing();
    return;
  }
  std::sort(others_.begin(), others_.end());
  owner_tid_ = static_cast<long>(::gettid());
  try {
    saved_.emplace_back(owner_tid_, cpusOf(owner_tid_));
    setCpus(owner_tid_, {cpu_});
    placeThreads(true);
  } catch (...) {  // out of memory reading /proc: no claim rather than a half-placed one
    restoreAll();
    claimNothing();
    return;
  }
  g_active = this;
}

CoreClaim::~CoreClaim() {
  std::lock_guard lock(g_mutex);
  if (cpu_ < 0) return;
  g_active = nullptr;
  try {
    restoreAll();
  } catch (...) {  // out of memory reading /proc: the threads keep their places
  }
  ::close(lock_fd_);  // releases the lock
}

void CoreClaim::restoreAll() {
  // Each thread as it was before the claim; those started during it on every CPU.
  const auto restore = [&](long tid) {
    const auto known =
        std::find_if(saved_.begin(), saved_.end(), [&](const auto& s) { return s.first == tid; });
    setCpus(tid, known != saved_.end() ? known->second : all_);
  };
  restore(owner_tid_);
  for (const long tid : otherThreads(owner_tid_)) restore(tid);
}

void CoreClaim::placeOtherThreads() {
  std::lock_guard lock(g_mutex);
  if (cpu_ < 0) return;
  placeThreads(false);
}

void CoreClaim::placeThreads(bool at_claim) {
  for (const long tid : otherThreads(owner_tid_)) {
    // A thread found later was started during the claim (its mask inherited): not saved.
    if (at_claim) saved_.emplace_back(tid, cpusOf(tid));
    setCpus(tid, others_);
  }
}

void CoreClaim::spawnOnOtherCpus(const std::function<void()>& spawn) {
  std::lock_guard lock(g_mutex);
  if (!g_active) {
    spawn();
    return;
  }
  // A child inherits the mask of the thread that starts it.
  struct Mask {
    std::vector<int> before = cpusOf(0);
    ~Mask() { setCpus(0, before); }
  } mask;
  setCpus(0, g_active->others_);
  spawn();
}

}  // namespace simsoccer::sim

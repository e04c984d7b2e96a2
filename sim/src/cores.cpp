#include "simsoccer/sim/cores.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
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

// The child processes of this process (the agents it started).
std::vector<long> childProcesses() {
  std::vector<long> pids;
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
    if (ppid == me) pids.push_back(std::strtol(name.c_str(), nullptr, 10));
  }
  std::sort(pids.begin(), pids.end());
  return pids;
}

std::filesystem::path taskFolder(long pid) {
  return std::filesystem::path("/proc") / std::to_string(pid) / "task";
}

// Every thread of this process but `skip`, and every thread of its child
// processes.
std::vector<long> otherThreads(long skip) {
  std::vector<long> tids = tasksIn("/proc/self/task");
  std::erase(tids, skip);
  for (const long pid : childProcesses()) {
    const std::vector<long> child = tasksIn(taskFolder(pid));
    tids.insert(tids.end(), child.begin(), child.end());
  }
  return tids;
}

// CPU time a thread has run, ns (the first field of schedstat); 0 for a
// thread that ended or a kernel without schedstat.
uint64_t runtimeNs(const std::filesystem::path& task) {
  std::ifstream in(task / "schedstat");
  uint64_t ns = 0;
  if (!(in >> ns)) return 0;
  return ns;
}

// Ticks (1/CLK_TCK s) CPU `cpu` spent running tasks (user, nice and system
// time in /proc/stat); 0 if unreadable.
uint64_t busyTicks(int cpu) {
  std::ifstream in("/proc/stat");
  const std::string name = "cpu" + std::to_string(cpu);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, name.size() + 1, name + " ") != 0) continue;
    std::istringstream fields(line.substr(name.size()));
    uint64_t user = 0, nice = 0, system = 0;
    fields >> user >> nice >> system;
    return user + nice + system;
  }
  return 0;
}

bool setPolicy(long tid, int policy) {
  const sched_param param{};
  return sched_setscheduler(static_cast<pid_t>(tid), policy, &param) == 0;
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
  for (const long pid : guests_)
    for (const long tid : tasksIn(taskFolder(pid))) (void)setPolicy(tid, SCHED_OTHER);
  guests_.clear();
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
  std::set<long> guest_threads;
  for (const long pid : guests_)
    for (const long tid : tasksIn(taskFolder(pid))) guest_threads.insert(tid);
  for (const long tid : otherThreads(owner_tid_)) {
    if (guest_threads.count(tid)) continue;
    // A thread found later was started during the claim (its mask inherited): not saved.
    if (at_claim) saved_.emplace_back(tid, cpusOf(tid));
    setCpus(tid, others_);
  }
}

bool CoreClaim::setGuest(long pid, bool guest) {
  bool ok = true;
  for (const long tid : tasksIn(taskFolder(pid))) {
    if (guest) {
      setCpus(tid, {cpu_});
      (void)setPolicy(tid, SCHED_IDLE);
    } else if (setPolicy(tid, SCHED_OTHER)) {
      setCpus(tid, others_);
    } else {
      ok = false;
    }
  }
  return ok;
}

size_t CoreClaim::balance() {
  std::lock_guard lock(g_mutex);
  if (cpu_ < 0) return 0;
  std::map<long, uint64_t> now;
  const auto used = [&](const std::filesystem::path& folder, long tid) {
    const uint64_t ns = runtimeNs(folder / std::to_string(tid));
    now[tid] = ns;
    const auto before = runtime_ns_.find(tid);
    const uint64_t from = before == runtime_ns_.end() ? 0 : before->second;
    return ns > from ? 1e-9 * static_cast<double>(ns - from) : 0.0;
  };
  // The claimed CPU's own load, and the rest's: this process's other threads
  // and every child, as if all were on the other CPUs.
  double claimed = 0.0, rest = 0.0;
  for (const long tid : tasksIn("/proc/self/task"))
    (tid == owner_tid_ ? claimed : rest) += used("/proc/self/task", tid);
  struct Child {
    long pid;
    double seconds = 0.0;
  };
  std::vector<Child> children;
  for (const long pid : childProcesses()) {
    Child c{pid};
    for (const long tid : tasksIn(taskFolder(pid))) c.seconds += used(taskFolder(pid), tid);
    rest += c.seconds;
    children.push_back(c);
  }
  runtime_ns_ = std::move(now);
  std::erase_if(guests_, [&](long pid) {
    return std::none_of(children.begin(), children.end(),
                        [&](const Child& c) { return c.pid == pid; });
  });
  // What else ran on the claimed CPU (other programs, runs that claimed
  // nothing): the CPU's busy time less the period thread's and the guests'.
  const double tick = 1.0 / static_cast<double>(::sysconf(_SC_CLK_TCK));  // s
  const uint64_t ticks = busyTicks(cpu_);
  const auto at = std::chrono::steady_clock::now();
  const double busy = static_cast<double>(ticks - busy_ticks_) * tick;
  const double window = std::chrono::duration<double>(at - measured_at_).count();
  busy_ticks_ = ticks;
  measured_at_ = at;
  if (!measured_) {
    measured_ = true;
    return guests_.size();
  }
  double foreign = busy - claimed;
  for (const Child& c : children)
    if (guests_.count(c.pid)) foreign -= c.seconds;
  foreign_share_ = window > 0 ? foreign / window : 0.0;
  // A guest at idle priority waits behind any other program on that CPU: none
  // where others use it (beyond two ticks of sampling error and 5 %).
  shared_ = foreign > 0.05 * window + 2.0 * tick;
  // Greedy, the present guests first (fewer moves): a child moves over while
  // that makes the busier side less busy.
  std::stable_partition(children.begin(), children.end(),
                        [&](const Child& c) { return guests_.count(c.pid) > 0; });
  const double cpus = static_cast<double>(others_.size());
  std::set<long> next;
  if (!shared_)
    for (const Child& c : children)
      if (std::max(claimed + c.seconds, (rest - c.seconds) / cpus) <
          std::max(claimed, rest / cpus)) {
        claimed += c.seconds;
        rest -= c.seconds;
        next.insert(c.pid);
      }
  for (const Child& c : children) {
    const bool was = guests_.count(c.pid) > 0, is = next.count(c.pid) > 0;
    if (is && !was) setGuest(c.pid, true);
    if (was && !is && !setGuest(c.pid, false)) next.insert(c.pid);  // may not be raised back
  }
  guests_ = std::move(next);
  return guests_.size();
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

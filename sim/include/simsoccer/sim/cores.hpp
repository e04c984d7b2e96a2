// A CPU of its own for the thread that runs a pipelined run's periods (Linux
// CPU affinity).
//
// In a pipelined period the world steps while the agents compute the next
// commands, so the two share the machine's cores. Left to the scheduler, a
// woken agent, a DDS thread or the frame sender often lands on the stepping
// thread's core and stalls the step (2 cores, 22 agent processes: the
// physics' 1.0 ms per period grew to 1.3-1.4 ms). A CoreClaim puts the
// calling thread on a CPU of its own and every other thread of this process,
// and of the processes it started (the agents), on the other CPUs; a process
// it starts during the claim goes there too (spawnOnOtherCpus).
//
// Runs side by side (tests, several matches) never share a claimed CPU: a
// lock file per CPU (flock, released when the process ends), and a run keeps
// its other threads off the CPUs other runs hold. A run that finds no CPU
// free for itself and one more for the rest, or a process allowed fewer than
// two CPUs, claims nothing and leaves placement to the scheduler. Placement
// changes when threads run, never what they compute.
//
// The claimed CPU idles while the period thread waits for the agents' answers.
// balance() lends that time to some of the child processes (the agents) as
// guests: pinned to the claimed CPU at SCHED_IDLE, so they run only while the
// period thread waits and never preempt it. How many comes from the CPU time
// every thread used since the last call, so that the busier side (the claimed
// CPU, or each of the others) is as little busy as it can be; none while other
// programs use the claimed CPU, since an idle-priority guest waits behind them.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace simsoccer::sim {

class CoreClaim {
 public:
  // Claims the highest CPU of this process's affinity set that no run holds
  // (lock files `simsoccer-cpu<N>.lock` in `lock_folder`; empty:
  // defaultLockFolder()), keeping the other free ones for the rest.
  explicit CoreClaim(const std::filesystem::path& lock_folder = {});
  // Every thread as it was before the claim (those started during it on
  // every CPU the claiming thread had); the lock released.
  ~CoreClaim();
  CoreClaim(const CoreClaim&) = delete;
  CoreClaim& operator=(const CoreClaim&) = delete;

  bool held() const { return cpu_ >= 0; }
  int cpu() const { return cpu_; }  // -1: none claimed
  const std::vector<int>& otherCpus() const { return others_; }
  // Puts the threads started since the claim (a thread the claiming thread
  // starts inherits its CPU) and those of processes started since on the
  // other CPUs (RunLoop: after the first period, which starts the cameras'
  // and the frame sender's threads).
  void placeOtherThreads();

  // Measures the CPU time (/proc's schedstat) each thread of this process
  // and of its child processes used since the last call and moves child
  // processes to or from the claimed CPU as guests, by the rule above. The
  // first call only measures. Returns the number of guests. A guest this
  // process may not raise back from SCHED_IDLE (not root) stays one.
  size_t balance();
  // Over the last balance's window: the share of wall time other programs
  // (and runs that claimed nothing) ran on the claimed CPU, and whether that
  // was enough to lend nothing (more than 5 % and two clock ticks).
  double foreignShare() const { return foreign_share_; }
  bool shared() const { return shared_; }

  // Runs `spawn` with the calling thread on the other CPUs of the claim in
  // force, if any, so that a process it starts inherits them.
  static void spawnOnOtherCpus(const std::function<void()>& spawn);

  // $XDG_RUNTIME_DIR, else the temporary folder.
  static std::filesystem::path defaultLockFolder();
  static std::filesystem::path lockFile(const std::filesystem::path& folder, int cpu);

 private:
  void placeThreads(bool at_claim);
  void restoreAll();
  // Pins every thread of child process `pid` to the claimed CPU at SCHED_IDLE
  // (guest), or puts it back on the other CPUs at SCHED_OTHER; false if it
  // could not be raised back.
  bool setGuest(long pid, bool guest);

  int cpu_ = -1;
  int lock_fd_ = -1;
  long owner_tid_ = 0;
  std::vector<int> all_, others_;
  std::vector<std::pair<long, std::vector<int>>> saved_;  // thread id, CPUs before the claim
  std::set<long> guests_;                                 // child processes on the claimed CPU
  std::map<long, uint64_t> runtime_ns_;                   // thread id: CPU time at the last balance
  bool measured_ = false;
  uint64_t busy_ticks_ = 0;  // the claimed CPU's busy ticks at the last balance
  std::chrono::steady_clock::time_point measured_at_;
  double foreign_share_ = 0.0;
  bool shared_ = false;
};

}  // namespace simsoccer::sim

// A CPU of its own for the thread that runs a pipelined run's periods (Linux
// CPU affinity).
//
// In a pipelined period the world steps while the agents compute the next
// commands, so the two share the machine's cores. Left to the scheduler, a
// woken agent, a DDS thread or the frame sender often lands on the stepping
// thread's core and stalls the step (2 cores, 22 agent processes: the
// physics' 1.05 ms per period grew to 1.3 ms). A CoreClaim puts the calling
// thread on a CPU of its own and every other thread of this process, and of
// the processes it started (the agents), on the rest; a process it starts
// during the claim goes there too (spawnOnOtherCpus).
//
// Runs side by side (tests, several matches) each claim a different CPU: a
// lock file per CPU (flock, released when the process ends). A run that
// finds none free, or a process allowed fewer than two CPUs, claims nothing
// and leaves placement to the scheduler. Placement changes when threads run,
// never what they compute.
#pragma once

#include <functional>
#include <vector>

namespace simsoccer::sim {

class CoreClaim {
 public:
  // Claims the highest free CPU of this process's affinity set, keeping at
  // least one for the rest.
  CoreClaim();
  // The masks as they were before the claim; the lock released.
  ~CoreClaim();
  CoreClaim(const CoreClaim&) = delete;
  CoreClaim& operator=(const CoreClaim&) = delete;

  bool held() const { return cpu_ >= 0; }
  int cpu() const { return cpu_; }  // -1: none claimed
  const std::vector<int>& otherCpus() const { return others_; }
  // Puts every other thread of this process and every thread of its child
  // processes on the other CPUs: at the claim, and again for those started
  // since (a thread the claiming thread starts inherits its CPU).
  void placeOtherThreads() const;

  // Runs `spawn` with the calling thread on the other CPUs of the claim in
  // force, if any, so that a process it starts inherits them.
  static void spawnOnOtherCpus(const std::function<void()>& spawn);

 private:
  int cpu_ = -1;
  int lock_fd_ = -1;
  long owner_tid_ = 0;
  std::vector<int> all_, others_;
};

}  // namespace simsoccer::sim

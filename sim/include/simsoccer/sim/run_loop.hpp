// The run loop every program uses: control periods back to back in lockstep
// (as fast as the drivers answer), or paced to the wall clock (real time, or
// a multiple of it). Pacing changes when a period runs, never what it
// computes: the step never reads the wall clock.
#pragma once

#include <functional>

#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::sim {

enum class Pacing : uint8_t { Lockstep, RealTime };

struct RunStats {
  long periods = 0;
  long late = 0;        // real time: periods that started late (the simulation fell behind)
  double wall_s = 0.0;  // wall time of the run
  int period_cpu = -1;  // pipelined: the CPU the periods had to themselves (-1: none; cores.hpp)
  size_t guests = 0;    // child processes (agents) lent its waits at the last balance (cores.hpp)
};

class RunLoop {
 public:
  // speed: simulated seconds per wall second when paced (1: real time).
  RunLoop(Simulation& sim, Pacing pacing, double speed = 1.0);

  // Runs periods until `stop()` says so (asked before each period) or
  // `max_periods` have run (< 0: no limit); `after_period` runs after each.
  RunStats run(const std::function<bool()>& stop, long max_periods = -1,
               const std::function<void()>& after_period = {});
  // Runs `periods` periods.
  RunStats run(long periods, const std::function<void()>& after_period = {}) {
    return run([] { return false; }, periods, after_period);
  }

 private:
  Simulation& sim_;
  Pacing pacing_;
  double speed_;
};

}  // namespace simsoccer::sim

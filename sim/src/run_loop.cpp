#include "simsoccer/sim/run_loop.hpp"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <thread>

#include "simsoccer/sim/cores.hpp"

namespace simsoccer::sim {

RunLoop::RunLoop(Simulation& sim, Pacing pacing, double speed)
    : sim_(sim), pacing_(pacing), speed_(speed) {
  if (!(speed > 0.0)) throw std::invalid_argument("real-time speed must be > 0");
}

RunStats RunLoop::run(const std::function<bool()>& stop, long max_periods,
                      const std::function<void()>& after_period) {
  using Clock = std::chrono::steady_clock;
  RunStats stats;
  // Pipelined, the world steps while the agents compute: on a CPU of its own.
  // Its solver then uses that one CPU (the same result with any number of threads).
  std::optional<CoreClaim> claim;
  if (sim_.mode() == Mode::Pipelined && sim_.config().own_core) claim.emplace();
  struct SolverThreads {  // restored after the run, also when a period throws
    engine::PhysicsWorld& physics;
    const int before = physics.activeSolverThreads();
    ~SolverThreads() { physics.setActiveSolverThreads(before); }
  } solver{sim_.world().physics()};
  if (claim && claim->held()) {
    solver.physics.setActiveSolverThreads(1);
    stats.period_cpu = claim->cpu();
  }
  const double period = sim_.world().scenario().physics.control_period;
  const auto start = Clock::now();
  const auto due = [&](long i) {
    return start + std::chrono::duration_cast<Clock::duration>(
                       std::chrono::duration<double>(static_cast<double>(i) * period / speed_));
  };
  for (long i = 0; max_periods < 0 || i < max_periods; ++i) {
    if (stop()) break;
    if (pacing_ == Pacing::RealTime) {
      if (Clock::now() > due(i) + std::chrono::milliseconds(1))
        ++stats.late;
      else
        std::this_thread::sleep_until(due(i));
    }
    sim_.period();
    // The threads the first period started (cameras, the frame sender) off the claimed CPU;
    // then, in lockstep, the claimed CPU's waits lent to agents (measured over 200 periods,
    // then every 1000). Paced, the periods leave time to spare, and a guest at idle
    // priority would wait behind any other program on that CPU.
    if (claim && i == 0) claim->placeOtherThreads();
    if (claim && pacing_ == Pacing::Lockstep && (i == 0 || i % 1000 == 200))
      stats.guests = claim->balance();  // the first call only measures
    ++stats.periods;
    if (after_period) after_period();
  }
  // Paced: the run ends when its last period's simulated time is due.
  if (pacing_ == Pacing::RealTime) std::this_thread::sleep_until(due(stats.periods));
  stats.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return stats;
}

}  // namespace simsoccer::sim

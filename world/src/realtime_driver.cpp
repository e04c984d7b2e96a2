#include "simsoccer/world/realtime_driver.hpp"

#include <cmath>
#include <stdexcept>
#include <thread>

namespace simsoccer::world {

RealTimeDriver::RealTimeDriver(World& world, double speed) : world_(world), speed_(speed) {
  if (!(speed > 0.0)) throw std::invalid_argument("real-time speed must be > 0");
}

long RealTimeDriver::run(double sim_seconds, const std::function<void(World&)>& before_period) {
  using Clock = std::chrono::steady_clock;
  const double period = world_.scenario().physics.control_period;
  const auto periods = static_cast<long>(std::lround(sim_seconds / period));
  const auto start = Clock::now();
  long late = 0;
  for (long i = 0; i < periods; ++i) {
    const auto due = start + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(i * period / speed_));
    if (Clock::now() > due + std::chrono::milliseconds(1))
      ++late;
    else
      std::this_thread::sleep_until(due);
    if (before_period) before_period(world_);
    world_.stepControlPeriod();
  }
  std::this_thread::sleep_until(start +
                                std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(periods * period / speed_)));
  return late;
}

}  // namespace simsoccer::world

// Paces a World to the wall clock: a separate, optional driver around the
// fixed-step simulation (the step itself never reads the wall clock).
#pragma once

#include <chrono>
#include <functional>

#include "simsoccer/world/world.hpp"

namespace simsoccer::world {

class RealTimeDriver {
 public:
  // speed: simulated seconds per wall-clock second (1 = real time).
  explicit RealTimeDriver(World& world, double speed = 1.0);

  // Runs control periods until `sim_seconds` more have been simulated,
  // calling `before_period` before each (commands go there) and sleeping so
  // that simulated time never runs ahead of the scaled wall clock.
  // Returns the number of periods that started late (the simulation could
  // not keep up).
  long run(double sim_seconds, const std::function<void(World&)>& before_period = {});

 private:
  World& world_;
  double speed_;
};

}  // namespace simsoccer::world

// The scene every robot-count benchmark uses: N Naos standing in
// side-by-side pairs on the field, every joint tracking a slow sinusoid
// (configs/bench/physics.yaml).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {

struct BenchConfig {
  std::filesystem::path file;
  world::Scenario base;
  std::vector<int> robots;
  double settle = 1.0;
  double seconds = 10.0;
  double pair_gap = 0.3;
  double frequency = 0.5;
  std::vector<std::pair<std::string, double>> motion;  // joint name, amplitude (rad)
};

BenchConfig loadBenchConfig(const std::filesystem::path& file);

// The base scenario with n robots in pairs on a 4 x 3 grid, teams alternating.
world::Scenario placeRobots(const BenchConfig& config, int n, double half_length,
                            double half_width);

// Commands every robot's joints: stand pose + amplitude * sin(2 pi f t + phase),
// one phase per robot, the amplitude ramping in over the settling time.
class BenchMotion {
 public:
  BenchMotion(const BenchConfig& config, const world::World& world);
  void command(world::World& world) const;

 private:
  struct Wave {
    int joint;
    double amplitude;
  };
  std::vector<Wave> waves_;
  double frequency_, settle_;
};

}  // namespace simsoccer::apps

#include "bench_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cli.hpp"
#include "simsoccer/engine/config.hpp"

namespace simsoccer::apps {

BenchConfig loadBenchConfig(const std::filesystem::path& file) {
  BenchConfig c;
  c.file = file;
  c.base = world::loadScenario(file);
  const auto root = engine::ConfigNode::loadFile(file);
  const auto b = root["bench"];
  b.allowOnly({"robots", "settle", "seconds", "pair_gap", "motion"});
  for (const auto& n : b["robots"].items()) {
    const int v = n.integer();
    if (v < 1) n.fail("robot counts must be >= 1");
    c.robots.push_back(v);
  }
  c.settle = b["settle"].nonNegative();
  c.seconds = b["seconds"].positive();
  c.pair_gap = b["pair_gap"].positive();
  const auto m = b["motion"];
  m.allowOnly({"frequency", "joints"});
  c.frequency = m["frequency"].positive();
  for (const auto& [name, amp] : m["joints"].entries()) c.motion.emplace_back(name, amp.number());
  return c;
}

world::Scenario placeRobots(const BenchConfig& c, int n, double half_length, double half_width) {
  world::Scenario s = c.base;
  s.robots.clear();
  const int columns = 4, rows = 3;
  int numbers[2] = {0, 0};
  for (int i = 0; i < n; ++i) {
    const int pair = i / 2;
    const int col = pair % columns, row = (pair / columns) % rows;
    const int layer = pair / (columns * rows);  // beyond 24 robots: shift the grid
    world::RobotPlacement p;
    p.team = i % 2;
    p.number = ++numbers[p.team];
    p.x = -half_length + (col + 0.5) * (2 * half_length / columns) + 0.4 * layer;
    p.y = -half_width + (row + 0.5) * (2 * half_width / rows) + (i % 2 ? 0.5 : -0.5) * c.pair_gap;
    p.yaw = 0.0;
    if (p.x > half_length - 0.1)
      throw UsageError("--robots " + std::to_string(n) + ": the benchmark's grid holds at most " +
                       std::to_string(i - i % 2) + " robots on this field");
    s.robots.push_back(p);
  }
  return s;
}

BenchMotion::BenchMotion(const BenchConfig& c, const world::World& w)
    : frequency_(c.frequency), settle_(c.settle) {
  const auto& model = *w.robot(0).model;
  for (const auto& [name, amp] : c.motion) {
    const int j = model.body->jointIndex(name);
    if (j < 0) {
      // The H21 has no wrists: skip joints the model lacks, never a typo of a real name.
      if (model.actuatorIndex(name) >= 0) continue;
      throw engine::ConfigError(c.file.string(), "bench.motion.joints." + name,
                                "unknown joint for robot model '" + model.name + "'");
    }
    waves_.push_back({j, amp});
  }
}

void BenchMotion::command(world::World& w) const {
  const double t = w.time();
  const double ramp = settle_ > 0 ? std::min(1.0, t / settle_) : 1.0;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& stand = w.robot(r).model->pose("stand");
    const double phase = 2.0 * std::numbers::pi * r / static_cast<double>(w.robotCount());
    const double s = ramp * std::sin(2.0 * std::numbers::pi * frequency_ * t + phase);
    for (const Wave& wave : waves_)
      w.setJointTarget(r, wave.joint, stand[static_cast<size_t>(wave.joint)] + wave.amplitude * s,
                       1.0);
  }
}

}  // namespace simsoccer::apps

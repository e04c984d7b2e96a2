// simsoccer bench sensors: the batched sonar tracer against Bullet's per-ray
// rayTest, and the cost of every other sensor, per robot count.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {
namespace {

const char* kBenchSensorsHelp =
    "usage: simsoccer bench sensors [--config FILE] [--robots 1,2,4,8,11,22] [--rays 9,32]\n"
    "                               [--seconds S] [--csv FILE]\n"
    "\n"
    "The physics benchmark's scene (N Naos in pairs, joints moving). Per N and per rays-per-sonar\n"
    "count K: microseconds per sonar update (every ray of every robot's two sonars, scene build\n"
    "included) for the batched tracer and for Bullet's per-ray rayTest, and their ratio (median\n"
    "of repeated updates). Then, over S simulated seconds with the scenario's own ray count:\n"
    "microseconds per control period for every other sensor (IMU, FSRs, bumpers, joints,\n"
    "currents, temperatures), the sonar's share per period, the physics time per period, and\n"
    "the whole sensor frame as a percentage of the physics time.\n"
    "\n"
    "  --config FILE   benchmark scenario (default configs/bench/physics.yaml)\n"
    "  --robots LIST   robot counts (default from the config)\n"
    "  --rays LIST     rays per sonar to compare (default 9,32)\n"
    "  --seconds S     simulated seconds for the per-period figures (default 2)\n"
    "  --csv FILE      also write the table as CSV (one row per robot count)\n";

using Clock = std::chrono::steady_clock;

template <class F>
double medianMicros(int repeats, F&& f) {
  std::vector<double> us;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    f();
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  }
  std::sort(us.begin(), us.end());
  return us[us.size() / 2];
}

// Builds the scene with n robots and lets it settle with the motion running.
world::World settledWorld(const BenchConfig& cfg, int n, int rays, const fields::FieldModel& f) {
  world::Scenario s = placeRobots(cfg, n, f.halfLength(), f.halfWidth());
  s.sensors.enabled = true;
  s.sensors.sonar_rays = rays;
  world::World w(s);
  const BenchMotion motion(cfg, w);
  const auto periods = static_cast<long>(cfg.settle / s.physics.control_period);
  for (long i = 0; i < periods; ++i) {
    motion.command(w);
    w.stepControlPeriod();
  }
  return w;
}

}  // namespace

int benchSensors(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"}, {"config", "robots", "rays", "seconds", "csv"});
  if (opt.help(kBenchSensorsHelp)) return 0;
  opt.noPositional();
  const auto config_file = findConfig(opt.get("config", ""), "configs/bench/physics.yaml");
  const BenchConfig cfg = loadBenchConfig(config_file);
  const std::vector<int> counts = opt.intList("robots", cfg.robots);
  const std::vector<int> ray_counts = opt.intList("rays", {9, 32});
  for (int k : ray_counts)
    if (k > 256) throw UsageError("--rays: at most 256 rays per sonar");
  const double seconds = opt.positive("seconds", 2.0);
  if (!(seconds > 0)) throw UsageError("--seconds must be > 0");
  const std::string csv = opt.get("csv", "");
  const fields::FieldModel field = fields::loadFieldModel(cfg.base.field_file);
  const int frame_rays = cfg.base.sensors.sonar_rays;
  std::printf(
      "simsoccer bench sensors: %s, sonar update every %.0f ms, %d rays per sonar in the "
      "frame, one thread\n",
      config_file.string().c_str(), cfg.base.sensors.sonar_period * 1e3, frame_rays);
  std::fflush(stdout);

  Table table;
  table.header = {"robots"};
  for (int k : ray_counts) {
    const std::string s = std::to_string(k);
    table.header.insert(table.header.end(), {"batched_us_rays" + s, "reference_us_rays" + s,
                                             "speedup_rays" + s, "hits_rays" + s});
  }
  table.header.insert(table.header.end(), {"other_sensors_us_per_period", "sonar_us_per_period",
                                           "physics_us_per_period", "sensor_share_pct"});
  for (const int n : counts) {
    std::vector<std::string> row{std::to_string(n)};
    std::vector<engine::RayHit> hits;
    for (const int k : ray_counts) {
      world::World w = settledWorld(cfg, n, k, field);
      auto& sensors = w.sensors();
      const double batched = medianMicros(200, [&] { sensors.traceBatched(w.physics(), hits); });
      size_t hit_count = 0;
      for (const auto& h : hits) hit_count += std::isfinite(h.distance);
      const double reference = medianMicros(20, [&] { sensors.traceReference(w.physics(), hits); });
      row.insert(row.end(), {fmt(batched, 1), fmt(reference, 1), fmt(reference / batched, 1),
                             std::to_string(hit_count)});
    }
    // The whole frame while the scene runs.
    world::World w = settledWorld(cfg, n, frame_rays, field);
    const BenchMotion motion(cfg, w);
    w.physics().resetStageTimes();
    w.physics().enableStageTimers(true);
    w.sensors().resetTimes();
    w.sensors().enableTimers(true);
    const auto periods = static_cast<long>(seconds / w.scenario().physics.control_period);
    for (long i = 0; i < periods; ++i) {
      motion.command(w);
      w.stepControlPeriod();
    }
    const auto& st = w.sensors().times();
    const auto& pt = w.physics().stageTimes();
    const double other_us = 1e6 * st.other_s / static_cast<double>(st.periods);
    const double sonar_us = 1e6 * st.sonar_s / static_cast<double>(st.periods);  // amortised
    const double physics_us = 1e6 * pt.total_s / static_cast<double>(st.periods);
    row.insert(row.end(), {fmt(other_us, 1), fmt(sonar_us, 1), fmt(physics_us, 1),
                           fmt(100.0 * (other_us + sonar_us) / physics_us, 2)});
    table.rows.push_back(row);
    std::fprintf(stderr, "  %d robots done\n", n);
  }
  table.finish(
      "batched/reference: one sonar update (all rays of all robots); speedup = reference / "
      "batched; hits = rays that found something in range. Per period: other sensors, the "
      "sonar's cost spread over the periods between updates, the physics steps; share = "
      "(other + sonar) / physics.",
      csv);
  return 0;
}

}  // namespace simsoccer::apps

// simsoccer bench physics: N Naos on the field, every joint tracking a slow
// sinusoid; prints steps/s, real-time factor and where the time goes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {
namespace {

const char* kBenchPhysicsHelp =
    "usage: simsoccer bench physics [--config FILE] [--robots 1,2,4,8,11,22] [--seconds S]\n"
    "                               [--dt 0.005,0.01] [--iterations N] [--joint-sweeps N]\n"
    "                               [--threads N]\n"
    "                               [--repeat N] [--csv FILE]\n"
    "\n"
    "Places N Naos on the field in side-by-side pairs, all joints tracking slow sinusoids\n"
    "around the stand pose, runs the settling time and then the timed interval. Prints per N\n"
    "and physics step: steps/s, real-time factor, ms per step, contacts per step (all, and\n"
    "robot against robot), the constraint batches solved side by side per step, robots\n"
    "standing at the end, and the share of the step spent in each stage; then, per N, the\n"
    "real-time factor at the project's default step (10 ms, run as well when --dt leaves it\n"
    "out) and each other step's against it.\n"
    "\n"
    "  --config FILE   benchmark scenario (default configs/bench/physics.yaml)\n"
    "  --robots LIST   robot counts (default from the config)\n"
    "  --seconds S     simulated seconds timed per robot count (default from the config)\n"
    "  --dt LIST       physics steps in seconds (default: the config's); the control period\n"
    "                  is the config's, rounded to a whole number of steps\n"
    "  --iterations N  constraint solver iterations (default: the config's)\n"
    "  --joint-sweeps N  sweeps over the joint rows per iteration (default: the config's;\n"
    "                  a 10 ms step needs 2, docs/models.md)\n"
    "  --threads N     solver threads (default: the config's physics.threads, else one per\n"
    "                  core up to 4); the result is the same for any number\n"
    "  --repeat N      time each robot count N times (fresh world each) and report the run\n"
    "                  with the median steps/s (default 1)\n"
    "  --csv FILE      also write the table as CSV (one row per robot count and step)\n";

// The physics settings of one row: the config's with this step, the control
// period a whole number of steps.
world::PhysicsConfig withStep(world::PhysicsConfig physics, double dt) {
  const double steps = std::max(1.0, std::round(physics.control_period / dt));
  physics.dt = dt;
  physics.control_period = steps * dt;
  return physics;
}

}  // namespace

int benchPhysics(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"},
                    {"config", "robots", "seconds", "dt", "iterations", "joint-sweeps", "threads",
                     "repeat", "csv"});
  if (opt.help(kBenchPhysicsHelp)) return 0;
  opt.noPositional();
  const auto config_file = findConfig(opt.get("config", ""), "configs/bench/physics.yaml");
  BenchConfig cfg = loadBenchConfig(config_file);
  const std::vector<int> counts = opt.intList("robots", cfg.robots);
  cfg.seconds = opt.positive("seconds", cfg.seconds);
  if (!(cfg.seconds > 0)) throw UsageError("--seconds must be > 0");
  cfg.base.physics.threads =
      opt.wholeNumber("threads", cfg.base.physics.threads, 1, world::PhysicsConfig::kMaxThreads);
  cfg.base.physics.solver_iterations =
      opt.wholeNumber("iterations", cfg.base.physics.solver_iterations, 1, 1000);
  cfg.base.physics.joint_sweeps =
      opt.wholeNumber("joint-sweeps", cfg.base.physics.joint_sweeps, 1, 16);
  const int threads = world::solverThreads(cfg.base.physics);
  // The project's default step is always measured, first, as the reference.
  const double default_dt = world::PhysicsConfig{}.dt;
  std::vector<double> steps = opt.positiveList("dt", {cfg.base.physics.dt});
  for (const double dt : steps)
    if (dt > 0.05) throw UsageError("--dt: at most 0.05 s, got " + std::to_string(dt));
  // Each step once, the default first, the others in the order given.
  std::vector<double> unique{default_dt};
  for (const double dt : steps)
    if (std::none_of(unique.begin(), unique.end(),
                     [&](double u) { return std::abs(dt - u) < 1e-12; }))
      unique.push_back(dt);
  steps = unique;
  const std::string csv = opt.get("csv", "");
  const int repeat = opt.wholeNumber("repeat", 1, 1, 1000);

  const fields::FieldModel field = fields::loadFieldModel(cfg.base.field_file);
  std::string step_list;
  for (const double dt : steps)
    step_list += (step_list.empty() ? "" : ", ") + engine::formatNumber(dt * 1e3);
  std::printf(
      "simsoccer bench physics: %s, field %s, dt %s ms, control %.1f ms (whole steps), %d solver "
      "iterations (%d sweep%s over the joint rows each), %d solver thread%s, %.1f s settling + "
      "%.1f s timed per row\n",
      config_file.string().c_str(), field.name.c_str(), step_list.c_str(),
      cfg.base.physics.control_period * 1e3, cfg.base.physics.solver_iterations,
      cfg.base.physics.joint_sweeps, cfg.base.physics.joint_sweeps == 1 ? "" : "s", threads,
      threads == 1 ? "" : "s", cfg.settle, cfg.seconds);
  std::fflush(stdout);

  Table table;
  table.header = {"robots",
                  "dt_ms",
                  "steps_per_s",
                  "real_time_factor",
                  "ms_per_step",
                  "contacts_per_step",
                  "robot_contacts_per_step",
                  "solver_batches_per_step",
                  "standing",
                  "collision_pct",
                  "dynamics_pct",
                  "solver_pct",
                  "integrate_pct",
                  "servo_pct",
                  "other_pct"};
  // One timed run with n robots at step dt: (steps/s, table row).
  auto measure = [&](int n, double dt) {
    BenchConfig run_cfg = cfg;
    run_cfg.base.physics = withStep(cfg.base.physics, dt);
    world::World w(placeRobots(run_cfg, n, field.halfLength(), field.halfWidth()));
    const BenchMotion motion(cfg, w);
    const int per_control = w.stepsPerControlPeriod();
    const auto settle_steps = static_cast<long>(std::lround(cfg.settle / dt));
    const auto timed_steps = static_cast<long>(std::lround(cfg.seconds / dt));
    for (long i = 0; i < settle_steps; ++i) {
      if (i % per_control == 0) motion.command(w);
      w.step();
    }
    w.physics().resetStageTimes();
    w.physics().enableStageTimers(true);
    long contacts = 0, robot_contacts = 0, batches = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < timed_steps; ++i) {
      if (i % per_control == 0) motion.command(w);
      w.step();
      const engine::ContactCount cc = w.physics().contactCount();
      contacts += cc.total;
      robot_contacts += cc.between_articulations;
      batches += w.physics().lastStepSolverBatches();
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    w.physics().enableStageTimers(false);
    int standing = 0;
    for (world::RobotId r = 0; r < w.robotCount(); ++r) standing += w.isStanding(r) ? 1 : 0;
    const auto& st = w.physics().stageTimes();
    const double steps_per_s = static_cast<double>(timed_steps) / wall;
    auto pct = [&](double x) { return fmt(100.0 * x / wall, 1); };
    const double other =
        wall - st.collision_s - st.dynamics_s - st.solver_s - st.integrate_s - st.servo_s;
    return std::pair<double, std::vector<std::string>>{
        steps_per_s,
        {std::to_string(n), engine::formatNumber(dt * 1e3), fmt(steps_per_s, 0),
         fmt(steps_per_s * dt, 2), fmt(1e3 * wall / static_cast<double>(timed_steps), 3),
         fmt(static_cast<double>(contacts) / static_cast<double>(timed_steps), 1),
         fmt(static_cast<double>(robot_contacts) / static_cast<double>(timed_steps), 2),
         fmt(static_cast<double>(batches) / static_cast<double>(timed_steps), 1),
         std::to_string(standing) + "/" + std::to_string(n), pct(st.collision_s),
         pct(st.dynamics_s), pct(st.solver_s), pct(st.integrate_s), pct(st.servo_s), pct(other)}};
  };
  std::string summary;  // per N: the default step's real-time factor, the others against it
  for (const int n : counts) {
    double default_rtf = 0.0;
    for (const double dt : steps) {
      std::vector<std::pair<double, std::vector<std::string>>> runs;
      for (int rep = 0; rep < repeat; ++rep) runs.push_back(measure(n, dt));
      std::sort(runs.begin(), runs.end(),
                [](const auto& a, const auto& b) { return a.first < b.first; });
      const auto& median = runs[runs.size() / 2];
      table.rows.push_back(median.second);
      std::fprintf(stderr, "  %d robots, dt %s ms done: %.0f steps/s (median of %d)\n", n,
                   engine::formatNumber(dt * 1e3).c_str(), median.first, repeat);
      const double rtf = median.first * dt;
      if (dt == steps.front()) {
        default_rtf = rtf;
        summary += std::to_string(n) + " robots: real-time factor " + fmt(rtf, 2) +
                   " at the default step (" + engine::formatNumber(dt * 1e3) + " ms)";
      } else {
        summary += "; " + fmt(rtf, 2) + " at " + engine::formatNumber(dt * 1e3) + " ms (" +
                   fmt(rtf / default_rtf, 2) + "x)";
      }
    }
    summary += "\n";
  }
  table.finish(
      "Stages: collision = broadphase + narrowphase; dynamics = articulated-body forward "
      "dynamics (the part outside the batches: each robot's own runs with its batch); "
      "solver = contact, joint-limit and implicit servo constraints (their batches side by "
      "side on the solver threads); integrate = positions; servo = joint PD torques; other "
      "= everything else in the step and the loop (commands, contact counting).",
      csv);
  std::printf("\n%s", summary.c_str());
  return 0;
}

}  // namespace simsoccer::apps

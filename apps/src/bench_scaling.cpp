// simsoccer bench scaling: the full pipeline per robot count (physics,
// sensors, perception, DDS with real agent processes playing soccer, the
// referee; cameras with --cameras), against the published USARSim figures.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_motion/trial.hpp"
#include "cli.hpp"
#include "domain_option.hpp"
#include "help_texts.hpp"
#include "scaling_plot.hpp"
#include "scaling_row.hpp"

namespace simsoccer::apps {

int benchScaling(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "cameras", "shared-cores"},
                    {"robots", "seconds", "csv", "png", "domain", "modes", "threads", "robot", "dt",
                     "joint-sweeps"});
  if (opt.help(kBenchScalingHelp)) return 0;
  opt.noPositional();
  const std::vector<int> counts = opt.intList("robots", {1, 2, 4, 8, 11, 22});
  for (int n : counts)
    if (n < 1 || n > 22) throw UsageError("--robots: 1..22 robots per row");
  const double seconds = opt.positive("seconds", 20.0);
  if (!(seconds > 0)) throw UsageError("--seconds must be > 0");
  const bool cameras = opt.flag("cameras");
  const bool own_core = !opt.flag("shared-cores");
  const int threads = opt.wholeNumber("threads", 0, 1, world::PhysicsConfig::kMaxThreads);
  std::vector<sim::Mode> modes;
  {
    std::string list = opt.get("modes", "serial,pipelined");
    size_t start = 0;
    while (start <= list.size()) {
      const size_t comma = std::min(list.find(',', start), list.size());
      try {
        modes.push_back(sim::parseMode(list.substr(start, comma - start)));
      } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--modes: ") + e.what());
      }
      start = comma + 1;
    }
  }
  ScalingRobot robot;
  const std::string robot_name = opt.get("robot", "nao_v6_h25");
  if (robot_name == "nao_v6_h25") {
    robot.robot_model = findConfig("", "robots/nao_v6_h25.yaml");
  } else {
    const std::filesystem::path bench =
        findConfig("", "configs/bench/motion_" + robot_name + ".yaml");
    if (!std::filesystem::exists(bench))
      throw UsageError("--robot " + robot_name + ": no " + bench.string() +
                       " (robots: nao_v6_h25, booster_k1)");
    const motion::MotionBench b = motion::loadMotionBench(bench);
    robot = {b.robot_model, b.field, b.agents};
  }
  robot.dt = opt.number("dt", 0.0);
  if (robot.dt != 0.0 && robot.dt != 0.005 && robot.dt != 0.01)
    throw UsageError("--dt: 0.005 or 0.01 (a whole part of the 10 ms control period)");
  robot.joint_sweeps = opt.wholeNumber("joint-sweeps", 0, 1, 16);
  const net::DomainClaim claim = claimDomain(opt, 43, DomainDefault::FirstFree);
  const uint32_t domain = claim.domain();
  const std::filesystem::path png = opt.get("png", "scaling.png");
  std::printf(
      "simsoccer bench scaling: %s, full pipeline (physics, sensors, perception, DDS lockstep "
      "with N soccer agent processes, referee%s), %.0f s simulated per row\n",
      robot_name.c_str(), cameras ? ", cameras" : "", seconds);
  std::fflush(stdout);
  Table table;
  table.header = {"robots",     "mode",       "steps_per_s",   "fps",          "rtf",
                  "physics_ms", "sensors_ms", "perception_ms", "messaging_ms", "referee_ms",
                  "render_ms",  "missed",     "cpu_ms",        "period_cpu",   "guests"};
  std::vector<ScalingRow> rows, plotted;
  for (int n : counts) {
    for (const sim::Mode mode : modes) {
      const ScalingRow r = runRow(n, seconds, cameras, mode, threads, domain, robot, own_core);
      rows.push_back(r);
      if (mode == modes.back()) plotted.push_back(r);
      table.rows.push_back({std::to_string(n), sim::modeName(r.mode), fmt(r.steps_per_s, 0),
                            fmt(r.fps, 0), fmt(r.rtf, 2), fmt(r.physics_ms, 2),
                            fmt(r.sensors_ms, 3), fmt(r.perception_ms, 3), fmt(r.messaging_ms, 2),
                            fmt(r.referee_ms, 3), fmt(r.render_ms, 2), std::to_string(r.missed),
                            r.cpu_ms >= 0 ? fmt(r.cpu_ms, 2) : "n/a",
                            r.period_cpu >= 0 ? std::to_string(r.period_cpu) : "-",
                            r.period_cpu >= 0 ? std::to_string(r.guests) : "-"});
      std::fprintf(stderr, "  %d robots, %s done\n", n, sim::modeName(mode));
    }
  }
  table.finish(
      "fps: control periods (frames) per wall second, 100 per simulated second; rtf: simulated / "
      "wall time; mode: serial or pipelined (the world steps while the agents compute); ms "
      "per control period: physics, sensors, perception, messaging (frames out, waiting "
      "for and applying the agents' commands; in pipelined mode the frames go out on a sender "
      "thread while the world steps, and only the wait left after the step counts), referee, "
      "render (cameras); "
      "missed: lockstep periods an agent did not answer in time; cpu_ms: CPU time of the "
      "simulator and all agent processes per period (against cores x wall ms per period: how "
      "full the machine was); period_cpu: the CPU a pipelined row's periods had to themselves "
      "(its solver on that one; the agents and the other threads on the rest; -: none); "
      "guests: agents that ran on that CPU at idle priority, in the periods' waits, at the "
      "row's last balance (sim/cores.hpp). "
      "USARSim (published): 1 Nao 110 fps, 2: 55, 3: 30, 4: 10.",
      opt.get("csv", ""));
  std::vector<ScalingPoint> points;
  for (const ScalingRow& r : plotted) points.push_back({r.robots, r.fps, r.rtf});
  writeScalingPlot(points, png);
  std::printf("plot: %s\n", png.string().c_str());
  return 0;
}

}  // namespace simsoccer::apps

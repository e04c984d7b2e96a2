// simsoccer bench net: the lockstep loop with N real agent processes over
// loopback DDS, against the same world stepped without the network.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "domain_option.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {
namespace {

// Agent processes and what they cost, from the match runner library.
using namespace simsoccer::match;

const char* kBenchNetHelp =
    "usage: simsoccer bench net [--config FILE] [--robots 1,2,4,8,11,22] [--seconds S]\n"
    "                           [--domain D] [--dds-config FILE] [--csv FILE]\n"
    "\n"
    "Per N: starts N simsoccer-agent processes (stand and nod), runs the lockstep loop for S\n"
    "simulated seconds (default 10) over loopback DDS, then the same world for S seconds\n"
    "without the network. Prints the messaging overhead per control period (total minus the\n"
    "world's stepping), the CPU time all processes spent on messaging per period (the\n"
    "simulator's and the agents' CPU time minus the CPU time of the world stepped alone: it\n"
    "does not grow when processes wait for a core), the bytes and packets per tick on the\n"
    "loopback interface, commands missed, and the real-time factor with and without the\n"
    "network. --domain D: the DDS domain (default the first free one on this host from 42).\n";

using Clock = std::chrono::steady_clock;

}  // namespace

int benchNet(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"},
                    {"config", "robots", "seconds", "domain", "dds-config", "csv"});
  if (opt.help(kBenchNetHelp)) return 0;
  opt.noPositional();
  const auto config_file = findConfig(opt.get("config", ""), "configs/bench/physics.yaml");
  BenchConfig cfg = loadBenchConfig(config_file);
  const std::vector<int> counts = opt.intList("robots", cfg.robots);
  const double sim_seconds = opt.positive("seconds", 10.0);
  if (!(sim_seconds > 0)) throw UsageError("--seconds must be > 0");
  net::DomainConfig dds;
  const net::DomainClaim claim = claimDomain(opt, 42, DomainDefault::FirstFree);
  dds.domain = claim.domain();
  dds.config_file = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  const std::string csv = opt.get("csv", "");
  const auto agent = agentProgram();
  const fields::FieldModel field = fields::loadFieldModel(cfg.base.field_file);
  std::printf("simsoccer bench net: %s, DDS domain %u (%s), %.1f s simulated per row, lockstep\n",
              config_file.string().c_str(), dds.domain, dds.config_file.string().c_str(),
              sim_seconds);
  std::fflush(stdout);

  Table table;
  table.header = {"robots",
                  "overhead_ms_per_period",
                  "publish_ms",
                  "wait_ms",
                  "world_ms_per_period",
                  "overhead_pct",
                  "net_cpu_ms_per_period",
                  "bytes_per_tick",
                  "packets_per_tick",
                  "missed",
                  "rtf_with_net",
                  "rtf_without_net"};
  for (const int n : counts) {
    world::Scenario s = placeRobots(cfg, n, field.halfLength(), field.halfWidth());
    s.sensors.enabled = true;
    const double period = s.physics.control_period;
    const auto periods = static_cast<long>(sim_seconds / period);

    // With the network.
    world::World w(s);
    net::ServerConfig server_cfg;
    server_cfg.dds = dds;
    server_cfg.command_timeout = 1.0;
    // Serial: the overhead measured is the messaging alone, not overlapped with the step.
    sim::SimulationConfig simc;
    simc.mode = sim::Mode::Serial;
    sim::Simulation simulation(w, simc);
    net::SimServer server(simulation, server_cfg);
    sim::RunLoop loop(simulation, sim::Pacing::Lockstep);
    std::vector<std::unique_ptr<ChildProcess>> agents;
    for (world::RobotId r = 0; r < w.robotCount(); ++r)
      agents.push_back(std::make_unique<ChildProcess>(std::vector<std::string>{
          agent.string(), "--team", std::to_string(w.robot(r).team), "--player",
          std::to_string(w.robot(r).number), "--domain", std::to_string(dds.domain), "--dds-config",
          dds.config_file.string()}));
    if (!server.waitForOwners(w.robotCount(), 60.0))
      throw std::runtime_error("only " + std::to_string(server.ownedCount()) + " of " +
                               std::to_string(w.robotCount()) + " agents claimed their robots");
    loop.run(50);  // warm-up
    const sim::Profile before = simulation.profile();
    // CPU time of the simulator and of every agent process, over the timed
    // periods only (not the start-up and its discovery traffic).
    const auto cpu_now = [&] { return cpuSecondsWithChildren(agents); };
    const long long bytes0 = loopbackBytes(), packets0 = loopbackPackets();
    const double cpu0 = cpu_now();
    const auto t0 = Clock::now();
    loop.run(periods);
    const double wall_net = std::chrono::duration<double>(Clock::now() - t0).count();
    const double cpu1 = cpu_now(), cpu_net = cpu0 >= 0 && cpu1 >= 0 ? cpu1 - cpu0 : -1.0;
    const long long bytes = loopbackBytes() - bytes0, packets = loopbackPackets() - packets0;
    const sim::Profile& after = simulation.profile();
    const double world_s = after.step_s - before.step_s;
    uint64_t missed = 0;
    for (world::RobotId r = 0; r < w.robotCount(); ++r) missed += server.stats(r).missed;
    agents.clear();

    // The same world without the network, with the same 50 untimed warm-up periods.
    world::World alone(s);
    for (int i = 0; i < 50; ++i) alone.stepControlPeriod();
    const auto t1 = Clock::now();
    const double cpu_alone0 = threadCpuSeconds();
    for (long i = 0; i < periods; ++i) alone.stepControlPeriod();
    const double cpu_alone = threadCpuSeconds() - cpu_alone0;
    const double wall_alone = std::chrono::duration<double>(Clock::now() - t1).count();

    const double overhead_ms = 1e3 * (wall_net - world_s) / periods;
    const double world_ms = 1e3 * wall_alone / periods;
    const double publish_ms = 1e3 * (after.observe_s - before.observe_s) / periods;
    const double wait_ms = 1e3 * (after.collect_s - before.collect_s) / periods;
    table.rows.push_back({std::to_string(n), fmt(overhead_ms, 3), fmt(publish_ms, 3),
                          fmt(wait_ms, 3), fmt(world_ms, 3), fmt(100.0 * overhead_ms / world_ms, 1),
                          // CPU against CPU: the world's CPU time alone, not its wall
                          // time with the network (that grows when the agents preempt it).
                          cpu_net >= 0 ? fmt(1e3 * (cpu_net - cpu_alone) / periods, 3) : "n/a",
                          bytes >= 0 ? std::to_string(bytes / periods) : "n/a",
                          packets >= 0 ? fmt(static_cast<double>(packets) / periods, 1) : "n/a",
                          std::to_string(missed), fmt(sim_seconds / wall_net, 2),
                          fmt(sim_seconds / wall_alone, 2)});
    std::fprintf(stderr, "  %d robots done\n", n);
  }
  table.finish(
      "overhead = wall time per period minus the world's stepping (publishing frames, "
      "waiting for and taking commands); world = the same world stepped alone (physics and "
      "sensors); net_cpu = CPU time of the simulator and all agents per period minus the CPU "
      "time of the world stepped alone; bytes, packets = loopback interface traffic per tick "
      "(all processes, RTPS headers, heartbeats, acknowledgements and discovery included).",
      csv);
  return 0;
}

}  // namespace simsoccer::apps

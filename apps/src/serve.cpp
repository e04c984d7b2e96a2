// simsoccer serve: a scenario as a DDS simulator, for agents started
// elsewhere (on this machine or others).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "cli.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/world/realtime_driver.hpp"

namespace simsoccer::apps {
namespace {

const char* kHelp =
    "usage: simsoccer serve SCENARIO [--domain D] [--dds-config FILE] [--seconds S]\n"
    "                       [--agents N] [--realtime] [--timeout S] [--limp-on-release]\n"
    "\n"
    "Runs the scenario's world as a DDS simulator: waits until N robots (default: all) are\n"
    "claimed by agents, then runs S simulated seconds (default 60) in lockstep (each period\n"
    "waits up to --timeout s of wall time, default 0.5, for every owned robot's command) or,\n"
    "with --realtime, paced to the wall clock with the latest commands. Ctrl-C stops it.\n"
    "Prints each robot's command counters at the end.\n";

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

}  // namespace

int serve(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "realtime", "limp-on-release"},
                    {"domain", "dds-config", "seconds", "agents", "timeout"});
  if (opt.help(kHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one scenario file");
  world::World w = world::World::fromFile(opt.positional()[0]);
  net::ServerConfig cfg;
  cfg.dds.domain = static_cast<uint32_t>(opt.number("domain", 0));
  cfg.dds.config_file = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  cfg.lockstep = !opt.flag("realtime");
  cfg.command_timeout = opt.number("timeout", 0.5);
  cfg.hold_on_release = !opt.flag("limp-on-release");
  const double sim_seconds = opt.number("seconds", 60.0);
  const auto wanted =
      static_cast<size_t>(opt.number("agents", static_cast<double>(w.robotCount())));
  net::SimServer server(w, cfg);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::printf("simsoccer serve: %zu robots on DDS domain %u, waiting for %zu agents...\n",
              w.robotCount(), cfg.dds.domain, wanted);
  std::fflush(stdout);
  while (!g_stop && !server.waitForOwners(wanted, 1.0)) {
  }
  const auto periods = static_cast<long>(sim_seconds / w.scenario().physics.control_period);
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < periods && !g_stop; ++i) {
    if (!cfg.lockstep) {
      // Pace each period to the wall clock.
      const auto due =
          t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                   std::chrono::duration<double>(i * w.scenario().physics.control_period));
      std::this_thread::sleep_until(due);
    }
    server.runPeriod();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("simulated %.2f s in %.2f s (real-time factor %.2f)\n", w.time(), wall,
              w.time() / wall);
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& s = server.stats(r);
    std::printf(
        "  team %d player %d: %s, accepted %llu, rejected %llu, refused %llu, missed %llu\n",
        w.robot(r).team, w.robot(r).number, s.owned ? "owned" : "free",
        (unsigned long long)s.accepted, (unsigned long long)s.rejected,
        (unsigned long long)s.refused, (unsigned long long)s.missed);
  }
  return 0;
}

}  // namespace simsoccer::apps

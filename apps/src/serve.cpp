// simsoccer serve: a scenario as a DDS simulator, for agents started
// elsewhere (on this machine or others).
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "cli.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {
namespace {

const char* kHelp =
    "usage: simsoccer serve SCENARIO [--domain D] [--dds-config FILE] [--seconds S]\n"
    "                       [--agents N] [--realtime] [--timeout S] [--limp-on-release]\n"
    "                       [--mode serial|pipelined]\n"
    "                       [--rules FILE [--teams A,B] [--auto-placement]\n"
    "                        [--gc-address ADDR [--gc-port P] [--gc-return-port P]]]\n"
    "\n"
    "Runs the scenario's world as a DDS simulator: waits until N robots (default: all) are\n"
    "claimed by agents, then runs S simulated seconds (default 60) in lockstep (each period\n"
    "waits up to --timeout s of wall time, default 0.5, for every owned robot's command) or,\n"
    "with --realtime, paced to the wall clock with the latest commands. Ctrl-C stops it.\n"
    "Prints each robot's command counters at the end. --mode pipelined: the world steps with\n"
    "the answers to the previous period's frames while the agents compute (one period of\n"
    "actuation delay; default serial).\n"
    "\n"
    "With --rules (e.g. configs/rules/spl.yaml) the automatic referee runs the game from the\n"
    "first kick-off to the end of the game, with a shoot-out if the rule book calls for one,\n"
    "as in `simsoccer match` (team 0 kicks off; --teams gives the GameController team numbers,\n"
    "default 1,2); serve stops when the game is over or after S s. Its state goes to agents on\n"
    "the GameState topic, and with --gc-address also as\n"
    "GameController packets over UDP (port 3838, every 0.5 simulated s; return packets on\n"
    "3939), so robot code written for the SPL GameController runs unchanged.\n";

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

}  // namespace

int serve(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "realtime", "limp-on-release", "auto-placement"},
                    {"domain", "dds-config", "seconds", "agents", "timeout", "rules", "teams",
                     "gc-address", "gc-port", "gc-return-port", "mode"});
  if (opt.help(kHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one scenario file");
  world::World w = world::World::fromFile(opt.positional()[0]);
  sim::SimulationConfig simc;
  simc.lockstep = !opt.flag("realtime");
  try {
    simc.mode = sim::parseMode(opt.get("mode", "serial"));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--mode: ") + e.what());
  }
  sim::Simulation simulation(w, simc);
  net::ServerConfig cfg;
  cfg.dds.domain = static_cast<uint32_t>(opt.number("domain", 0));
  cfg.dds.config_file = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  cfg.lockstep = !opt.flag("realtime");
  cfg.command_timeout = opt.number("timeout", 0.5);
  cfg.hold_on_release = !opt.flag("limp-on-release");
  const double sim_seconds = opt.number("seconds", 60.0);
  const auto wanted =
      static_cast<size_t>(opt.number("agents", static_cast<double>(w.robotCount())));
  net::SimServer server(simulation, cfg);

  // The officials (optional): the game from the first kick-off, as in a match.
  std::unique_ptr<sim::GameOfficials> officials;
  std::unique_ptr<referee::GameControllerLink> gc_link;
  if (opt.has("rules")) {
    const referee::RuleBook rules = referee::loadRuleBook(findConfig(opt.get("rules", ""), ""));
    const std::vector<int> numbers = opt.intList("teams", {1, 2});
    if (numbers.size() != 2 || numbers[0] < 0 || numbers[0] > 255 || numbers[1] < 0 ||
        numbers[1] > 255 || numbers[0] == numbers[1])
      throw UsageError("--teams: two different team numbers 0..255");
    sim::OfficialsConfig oc;
    for (size_t t = 0; t < 2; ++t) {
      oc.teams[t].number = static_cast<uint8_t>(numbers[t]);
      oc.teams[t].field_player_colour = static_cast<uint8_t>(t);
    }
    oc.referee.auto_placement = opt.flag("auto-placement");
    oc.seed = w.scenario().seed;
    officials = std::make_unique<sim::GameOfficials>(w, rules, oc);
    simulation.setOfficials(officials.get());
    server.publishGameState(officials->controlData(), officials->leftTeam());
    if (opt.has("gc-address")) {
      referee::GameControllerLinkConfig gcfg;
      gcfg.address = opt.get("gc-address", "");
      gcfg.control_port = static_cast<uint16_t>(opt.number("gc-port", 3838));
      gcfg.return_port = static_cast<uint16_t>(opt.number("gc-return-port", 3939));
      gc_link = std::make_unique<referee::GameControllerLink>(gcfg);
    }
  } else if (opt.has("gc-address")) {
    throw UsageError("--gc-address needs --rules (the referee makes the packets)");
  }
  if (gc_link) gc_link->update(officials->game());

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::printf("simsoccer serve: %zu robots on DDS domain %u, waiting for %zu agents...\n",
              w.robotCount(), cfg.dds.domain, wanted);
  std::fflush(stdout);
  while (!g_stop && !server.waitForOwners(wanted, 1.0)) {
  }
  const auto periods = static_cast<long>(sim_seconds / w.scenario().physics.control_period);
  sim::RunLoop loop(simulation, cfg.lockstep ? sim::Pacing::Lockstep : sim::Pacing::RealTime);
  const sim::RunStats run = loop.run(
      [&] { return g_stop || (officials && officials->over()); }, periods,
      [&] {
        if (gc_link) gc_link->update(officials->game());
      });
  simulation.flushCameras();
  const double wall = run.wall_s;
  std::printf("simulated %.2f s in %.2f s (real-time factor %.2f)\n", w.time(), wall,
              w.time() / wall);
  if (const world::CameraSystem* cams = simulation.cameras()) {
    const world::CameraStats c = cams->stats();
    std::printf(
        "cameras (%s): %llu images in %llu batched frames, %.1f ms draw + %.1f ms readback + "
        "%.1f ms conversion per frame, %llu captures dropped\n",
        cams->glRenderer().c_str(), (unsigned long long)c.views, (unsigned long long)c.captures,
        c.draw_ms / std::max<double>(1, c.captures),
        c.readback_ms / std::max<double>(1, c.captures),
        c.convert_ms / std::max<double>(1, c.captures), (unsigned long long)c.dropped);
  }
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& s = server.stats(r);
    std::printf(
        "  team %d player %d: %s, accepted %llu, rejected %llu, refused %llu, missed %llu\n",
        w.robot(r).team, w.robot(r).number, s.owned ? "owned" : "free",
        (unsigned long long)s.accepted, (unsigned long long)s.rejected,
        (unsigned long long)s.refused, (unsigned long long)s.missed);
  }
  if (officials) {
    const referee::Game& g = officials->game();
    std::printf("game: %s, score %d:%d, %zu referee events\n", referee::stateName(g.state()),
                g.score(0), g.score(1), g.events().size());
    for (const auto& e : g.events())
      std::printf("  %8.2f s  %-12s team %2d player %2d  %s\n", e.time, referee::eventName(e.type), e.team,
                  e.player, e.detail.c_str());
    if (gc_link)
      std::printf("GameController packets sent %llu; return packets accepted %llu, rejected %llu\n",
                  (unsigned long long)gc_link->packetsSent(),
                  (unsigned long long)gc_link->returnsAccepted(),
                  (unsigned long long)gc_link->returnsRejected());
    if (gc_link && gc_link->returnsRejected() > 0)
      std::printf("last rejected return packet: %s\n", gc_link->lastReturnError().c_str());
  }
  return 0;
}

}  // namespace simsoccer::apps

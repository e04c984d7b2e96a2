// simsoccer serve: a scenario (or a whole match) as a DDS simulator, for
// agents started elsewhere (on this machine or others).
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>

#include "booster_robots.hpp"
#include "cli.hpp"
#include "domain_option.hpp"
#include "help_texts.hpp"
#include "lola_option.hpp"
#include "serve_report.hpp"
#include "serve_world.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/match/match_runner.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {
namespace {

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

}  // namespace

int serve(int argc, char** argv, int first) {
  const Options opt(argc, argv, first,
                    {"help", "realtime", "limp-on-release", "auto-placement", "lola-net",
                     "booster-lockstep", "booster-netns"},
                    {"domain", "dds-config", "seconds", "agents", "timeout", "rules", "teams",
                     "gc-address", "gc-port", "gc-return-port", "mode", "seed", "half", "lola",
                     "out", "external-gc", "booster", "booster-domain"});
  if (opt.help(kServeHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one scenario or match config file");
  const std::filesystem::path file = opt.positional()[0];
  net::ServerConfig cfg;
  cfg.dds.config_file = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  std::optional<uint16_t> external_gc;
  if (opt.has("external-gc")) {
    external_gc = static_cast<uint16_t>(opt.wholeNumber("external-gc", 3838, 1, 65535));
    if (*external_gc == 3939)
      throw UsageError(
          "--external-gc 3939: the GameController's own port (it hears the robots "
          "there); its packets come on 3838");
    if (opt.has("gc-address"))
      throw UsageError(
          "--external-gc: an external GameController sends the packets, not --gc-address");
  }
  cfg.lockstep = !opt.flag("realtime") && !external_gc;
  cfg.hold_on_release = !opt.flag("limp-on-release");
  cfg.notice = [](const std::string& s) { std::fprintf(stderr, "simsoccer: %s\n", s.c_str()); };

  // The world and its officials: a match's, or a scenario's with optional rules.
  ServedWorld served = openServedWorld(opt, file, external_gc, cfg);
  sim::GameOfficials* officials = served.officials;
  if (opt.has("timeout")) cfg.command_timeout = opt.positive("timeout", 0.5);
  if (external_gc && !officials)
    throw UsageError("--external-gc needs --rules or a match config (the game it runs)");
  if (opt.has("gc-address") && !officials)
    throw UsageError(
        "--gc-address needs --rules or a match config (the referee makes the packets)");
  // Range-checked whether or not a GameController link below uses them.
  const auto gc_port = static_cast<uint16_t>(opt.wholeNumber("gc-port", 3838, 1, 65535));
  const auto gc_return_port =
      static_cast<uint16_t>(opt.wholeNumber("gc-return-port", 3939, 0, 65535));
  world::World& w = served.world();
  const std::unique_ptr<match::MatchSession>& session = served.session;
  const std::array<int, 2> team_numbers = served.team_numbers;
  // Booster SDK clients run on the wall clock: real time unless --booster-lockstep.
  const std::vector<world::RobotId> booster_robots = boosterRobots(opt, w, team_numbers);
  if (!booster_robots.empty() && !opt.flag("booster-lockstep")) cfg.lockstep = false;

  sim::SimulationConfig simc;
  simc.lockstep = cfg.lockstep;
  try {
    simc.mode = sim::parseMode(opt.get("mode", sim::modeName(sim::defaultMode(cfg.lockstep))));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--mode: ") + e.what());
  }
  sim::Simulation simulation(w, simc);
  if (session)
    session->attach(simulation);
  else
    simulation.setOfficials(officials);
  std::unique_ptr<match::LolaRobots> lola_robots;
  if (session) {
    lola_robots =
        match::openLolaRobots(*session, simulation, opt.get("out", "runs/serve"), cfg.lockstep,
                              [](const std::string& line) { std::printf("%s\n", line.c_str()); });
    cfg.not_served = session->lolaRobots();
  }
  for (world::RobotId r : booster_robots)
    for (world::RobotId l : cfg.not_served)
      if (r == l) throw UsageError("--booster and --lola name the same robot");
  const auto booster = openBoosterRobots(opt, w, simulation, booster_robots, cfg.dds.config_file,
                                         cfg.command_timeout, team_numbers);
  cfg.not_served.insert(cfg.not_served.end(), booster_robots.begin(), booster_robots.end());
  const double sim_seconds = opt.positive("seconds", 60.0);
  if (sim_seconds > 1e7) throw UsageError("--seconds: at most 10000000 (115 days)");
  const int servable = static_cast<int>(w.robotCount() - cfg.not_served.size());
  const auto wanted = static_cast<size_t>(opt.wholeNumber("agents", servable, 0, servable));
  // Agents started elsewhere are told the domain: it is what it says or refused. Claimed once
  // the config and the options are known good: a bad config is told as such, not as a domain
  // another run holds (CI ran a test's serve beside a match on domain 0).
  const net::DomainClaim domain = claimDomain(opt, 0, DomainDefault::Fixed);
  cfg.dds.domain = domain.domain();
  net::SimServer server(simulation, cfg);
  // Images still on their way reach the transports (their sinks) before those
  // go, also when the run ends with an exception.
  const FlushCamerasOnExit flush_cameras{simulation};
  std::unique_ptr<referee::GameControllerLink> gc_link;
  std::unique_ptr<sim::FieldTeamMessages> team_messages;
  if (officials) {
    server.publishGameState(officials->controlData(), officials->leftTeam());  // before agents
    // On the Booster robots' field network the packets go to its broadcast
    // address (unless --gc-address says otherwise), as a GameController's do.
    const bool field = booster && booster->bridge && !external_gc;
    if (opt.has("gc-address") || field) {
      referee::GameControllerLinkConfig gcfg;
      gcfg.address = opt.get("gc-address", field ? booster->bridge->network().broadcast() : "");
      if (field) {
        gcfg.return_bind = booster->bridge->network().hostAddress();
        gcfg.team_message_bind = booster->bridge->network().broadcast();
        gcfg.team_message_device = booster->bridge->network().bridge;
      }
      gcfg.control_port = gc_port;
      gcfg.return_port = gc_return_port;
      gc_link = std::make_unique<referee::GameControllerLink>(gcfg);
      gc_link->update(officials->game());
      // The programs' team messages count against each team's budget.
      if (field) {
        team_messages = std::make_unique<sim::FieldTeamMessages>(*gc_link, officials->game());
        simulation.addSource(*team_messages);
      }
    }
  }

  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::printf(
      "simsoccer serve: %zu robots on DDS domain %u, seed %llu, waiting for %zu agents...\n",
      w.robotCount(), cfg.dds.domain, static_cast<unsigned long long>(w.scenario().seed), wanted);
  std::fflush(stdout);
  while (!g_stop && !server.waitForOwners(wanted, 1.0)) {
  }
  while (lola_robots && !g_stop && !lola_robots->endpoint().waitForClients(1.0)) {
  }
  const auto periods = static_cast<long>(sim_seconds / w.scenario().physics.control_period + 0.5);
  sim::RunLoop loop(simulation, cfg.lockstep ? sim::Pacing::Lockstep : sim::Pacing::RealTime);
  const sim::RunStats run =
      loop.run([&] { return g_stop || (officials && officials->over()); }, periods,
               [&] {
                 if (gc_link) gc_link->update(officials->game());
                 if (lola_robots) lola_robots->afterPeriod();
               });
  simulation.flushCameras();
  std::printf("simulated %.2f s in %.2f s (real-time factor %.2f)\n", w.time(), run.wall_s,
              w.time() / run.wall_s);
  printCameraStats(simulation);
  printCounters(w, server);
  if (booster) printBoosterStats(*booster);
  if (lola_robots) printLolaResults(lola_robots->results());
  if (officials) printGame(officials->game());
  if (gc_link) printGameControllerLink(*gc_link);
  printFinalState(w);
  return 0;
}

}  // namespace simsoccer::apps

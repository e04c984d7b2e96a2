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

bool isMatchConfig(const std::filesystem::path& file) {
  return engine::ConfigNode::loadFile(file).has("match");
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
  if (!opt.has("booster") &&
      (opt.has("booster-domain") || opt.flag("booster-lockstep") || opt.flag("booster-netns")))
    throw UsageError("--booster-domain, --booster-lockstep and --booster-netns go with --booster");
  const std::filesystem::path file = opt.positional()[0];
  if (opt.flag("lola-net") && !opt.has("lola") && !isMatchConfig(file))
    throw UsageError("--lola-net goes with --lola");
  net::ServerConfig cfg;
  // Agents started elsewhere are told the domain: it is what it says or refused.
  const net::DomainClaim domain = claimDomain(opt, 0, DomainDefault::Fixed);
  cfg.dds.domain = domain.domain();
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
  cfg.notice = [](const std::string& line) {
    std::fprintf(stderr, "simsoccer: %s\n", line.c_str());
  };

  // The world and its officials: a match's, or a scenario's with optional rules.
  std::unique_ptr<match::MatchSession> session;
  std::unique_ptr<world::World> own_world;
  std::unique_ptr<sim::GameOfficials> own_officials;
  sim::GameOfficials* officials = nullptr;
  if (isMatchConfig(file)) {
    if (opt.has("rules")) throw UsageError("--rules: a match config names its own rule book");
    if (opt.has("teams")) throw UsageError("--teams: a match config names its own teams");
    match::MatchConfig mc = match::loadMatchConfig(file);
    if (opt.has("half")) {
      const double h = opt.number("half", 0);
      if (!(h > 0)) throw UsageError("--half must be > 0 s");
      mc.half_duration = h;
    }
    addLolaRobots(opt, mc);
    mc.external_gc_port = external_gc;
    session = std::make_unique<match::MatchSession>(mc, opt.seed("seed", mc.seed));
    officials = &session->officials();
    cfg.command_timeout = mc.command_timeout;
    cfg.team_message_delay = mc.message_delay;
    cfg.team_message_loss = mc.message_loss;
  } else {
    if (opt.has("half") || opt.has("lola"))
      throw UsageError("--half and --lola go with a match config");
    world::Scenario scenario = world::loadScenario(file);
    if (opt.has("seed")) scenario.seed = opt.seed("seed", 0);
    own_world = std::make_unique<world::World>(scenario);
    if (opt.has("rules")) {
      const referee::RuleBook rules = referee::loadRuleBook(findConfig(opt.get("rules", ""), ""));
      // More robots than the rule book's team size would be substitutes (match refuses it too).
      for (int team = 0; team < 2; ++team)
        if (std::count_if(scenario.robots.begin(), scenario.robots.end(),
                          [&](const auto& r) { return r.team == team; }) > rules.players_per_team)
          throw UsageError("--rules " + opt.get("rules", "") + ": " +
                           std::to_string(rules.players_per_team) + " players a team, but " +
                           file.string() + " has more in team " + std::to_string(team));
      const std::vector<int> numbers = opt.intList("teams", {1, 2});
      if (numbers.size() != 2 || numbers[0] < 0 || numbers[0] > 255 || numbers[1] < 0 ||
          numbers[1] > 255 || numbers[0] == numbers[1])
        throw UsageError("--teams: two different team numbers 0..255");
      sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(static_cast<uint8_t>(numbers[0]),
                                                               static_cast<uint8_t>(numbers[1]));
      oc.referee.auto_placement = opt.flag("auto-placement");
      oc.seed = scenario.seed;
      oc.external_gc_port = external_gc;
      own_officials = std::make_unique<sim::GameOfficials>(*own_world, rules, oc);
      officials = own_officials.get();
    }
  }
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
  world::World& w = session ? session->world() : *own_world;
  // GameController team numbers of the scenario's teams 0 and 1.
  std::array<int, 2> team_numbers{1, 2};
  if (session) {
    team_numbers = session->config().team_numbers;
  } else if (opt.has("teams")) {  // (a match config's own teams: refused above)
    const std::vector<int> numbers = opt.intList("teams", {1, 2});
    if (numbers.size() != 2 || numbers[0] < 0 || numbers[0] > 254 || numbers[1] < 0 ||
        numbers[1] > 254 || numbers[0] == numbers[1])
      throw UsageError("--teams: two different team numbers 0..254");
    team_numbers = {numbers[0], numbers[1]};
  }
  // Booster SDK clients run on the wall clock: real time unless --booster-lockstep.
  const std::vector<world::RobotId> booster_robots = boosterRobots(opt, w, team_numbers);
  if (!booster_robots.empty() && !opt.flag("booster-lockstep")) cfg.lockstep = false;

  sim::SimulationConfig simc;
  simc.lockstep = cfg.lockstep;
  try {
    simc.mode = sim::parseMode(opt.get("mode", sim::modeName(sim::kDefaultMode)));
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

  const double sim_seconds = opt.positive("seconds", 60.0);
  if (sim_seconds > 1e7) throw UsageError("--seconds: at most 10000000 (115 days)");
  const int servable = static_cast<int>(w.robotCount() - cfg.not_served.size());
  const auto wanted = static_cast<size_t>(opt.wholeNumber("agents", servable, 0, servable));
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

// `simsoccer serve`'s world: a match config's session, or a scenario with optional rules.
#include "serve_world.hpp"

#include "lola_option.hpp"
#include "simsoccer/engine/config.hpp"

namespace simsoccer::apps {

namespace {

// --teams A,B (default 1,2): the GameController team numbers of the scenario's teams 0 and 1.
std::array<int, 2> teamNumbers(const Options& opt) {
  const std::vector<int> n = opt.intList("teams", {1, 2});
  if (n.size() != 2 || n[0] < 0 || n[0] > 254 || n[1] < 0 || n[1] > 254 || n[0] == n[1])
    throw UsageError("--teams: two different team numbers 1..254");
  return {n[0], n[1]};
}

}  // namespace

ServedWorld openServedWorld(const Options& opt, const std::filesystem::path& file,
                            std::optional<uint16_t> external_gc, net::ServerConfig& cfg) {
  ServedWorld s;
  if (engine::ConfigNode::loadFile(file).has("match")) {
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
    s.session = std::make_unique<match::MatchSession>(mc, opt.seed("seed", mc.seed));
    s.officials = &s.session->officials();
    s.team_numbers = mc.team_numbers;
    cfg.command_timeout = mc.command_timeout;
    cfg.team_message_delay = mc.message_delay;
    cfg.team_message_loss = mc.message_loss;
  } else {
    if (opt.has("half") || opt.has("lola"))
      throw UsageError("--half and --lola go with a match config");
    if (opt.flag("lola-net")) throw UsageError("--lola-net goes with --lola and a match config");
    s.team_numbers = teamNumbers(opt);
    world::Scenario scenario = world::loadScenario(file);
    if (opt.has("seed")) scenario.seed = opt.seed("seed", 0);
    s.own_world = std::make_unique<world::World>(scenario);
    if (opt.has("rules")) {
      const referee::RuleBook rules = referee::loadRuleBook(findConfig(opt.get("rules", ""), ""));
      match::checkTeamSizes(rules, scenario);
      sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(
          static_cast<uint8_t>(s.team_numbers[0]), static_cast<uint8_t>(s.team_numbers[1]));
      oc.referee.auto_placement = opt.flag("auto-placement");
      oc.seed = scenario.seed;
      oc.external_gc_port = external_gc;
      s.own_officials = std::make_unique<sim::GameOfficials>(*s.own_world, rules, oc);
      s.officials = s.own_officials.get();
    }
  }
  return s;
}

}  // namespace simsoccer::apps

#include "booster_robots.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "simsoccer/lola/field_network.hpp"

namespace simsoccer::apps {

std::pair<int, int> parseTeamPlayer(const std::string& item, const std::string& option) {
  int team = -1, player = -1;
  char rest = 0;
  if (std::sscanf(item.c_str(), "%d:%d%c", &team, &player, &rest) != 2 || team < 0 || team > 1 ||
      player < 1 || player > 99)
    throw UsageError(option + ": '" + item +
                     "' is not T:P (the scenario's team 0 or 1, a player number 1..99)");
  return {team, player};
}

std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w) {
  std::vector<world::RobotId> out;
  if (!opt.has("booster")) return out;
  const std::string spec = opt.get("booster", "");
  if (spec == "all") {
    for (world::RobotId r = 0; r < w.robotCount(); ++r) out.push_back(r);
    return out;
  }
  for (size_t at = 0; at <= spec.size();) {
    const size_t end = std::min(spec.find(',', at), spec.size());
    const std::string item = spec.substr(at, end - at);
    at = end + 1;
    const auto [team, player] = parseTeamPlayer(item, "--booster");
    bool found = false;
    for (world::RobotId r = 0; r < w.robotCount(); ++r)
      if (w.robot(r).team == team && w.robot(r).number == player) {
        for (world::RobotId seen : out)
          if (seen == r) throw UsageError("--booster: " + item + " is named twice");
        out.push_back(r);
        found = true;
      }
    if (!found) throw UsageError("--booster: the scenario has no robot " + item);
  }
  return out;
}

std::string boosterNamespace(int team, int player) {
  return "simsoccer-booster-" + std::to_string(team) + "-" + std::to_string(player);
}

BoosterRobots::~BoosterRobots() {
  endpoint.reset();  // its sockets first
  for (const std::string& name : namespaces) {
    try {
      lola::runTool({"ip", "netns", "delete", name});
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
    }
  }
}

std::unique_ptr<BoosterRobots> openBoosterRobots(const Options& opt, const world::World& w,
                                                 sim::Simulation& simulation,
                                                 const std::vector<world::RobotId>& robots,
                                                 const std::filesystem::path& dds_config,
                                                 double answer_timeout) {
  if (robots.empty()) return nullptr;
  auto out = std::make_unique<BoosterRobots>();
  const bool netns = opt.flag("booster-netns");
  const auto base = static_cast<uint32_t>(opt.wholeNumber("booster-domain", 0, 0, 230));
  if (base + robots.size() - 1 > 230)
    throw UsageError("--booster-domain: " + std::to_string(robots.size()) +
                     " robots from domain " + std::to_string(base) + " pass domain 230");
  booster::EndpointConfig ec;
  ec.dds_config = dds_config;
  ec.lockstep = opt.flag("booster-lockstep");
  ec.answer_timeout = answer_timeout;
  if (!(ec.answer_timeout > 0.0 && ec.answer_timeout <= 60.0))
    throw UsageError("--timeout: more than 0 and at most 60 s with --booster");
  for (size_t i = 0; i < robots.size(); ++i) {
    booster::BoosterRobot b;
    b.robot = robots[i];
    b.domain = base + static_cast<uint32_t>(i);
    if (netns) {
      // Its own namespace with only loopback (a killed run's is replaced).
      b.network_namespace = boosterNamespace(w.robot(b.robot).team, w.robot(b.robot).number);
      try {
        lola::runTool({"ip", "netns", "delete", b.network_namespace});
      } catch (const std::runtime_error&) {  // none there
      }
      lola::runTool({"ip", "netns", "add", b.network_namespace});
      out->namespaces.push_back(b.network_namespace);
      lola::runTool({"ip", "-n", b.network_namespace, "link", "set", "lo", "up"});
    }
    ec.robots.push_back(b);
  }
  out->endpoint = std::make_unique<booster::Endpoint>(w, ec);
  simulation.addSource(*out->endpoint);
  if (w.scenario().cameras.enabled) out->endpoint->attachCameras(simulation);
  for (const booster::BoosterRobot& b : ec.robots) {
    const auto& info = w.robot(b.robot);
    if (netns)
      std::printf(
          "Booster SDK: team %d player %d (%s) as DDS domain 0 in network namespace %s: "
          "simsoccer booster-run --robot %d:%d -- PROGRAM\n",
          info.team, info.number, info.model->name.c_str(), b.network_namespace.c_str(),
          info.team, info.number);
    else
      std::printf("Booster SDK: team %d player %d (%s) on DDS domain %u\n", info.team,
                  info.number, info.model->name.c_str(), b.domain);
  }
  return out;
}

void printBoosterStats(const BoosterRobots& robots, const world::World& w) {
  const booster::Endpoint& endpoint = *robots.endpoint;
  for (size_t i = 0; i < endpoint.config().robots.size(); ++i) {
    const booster::BoosterRobot& b = endpoint.config().robots[i];
    const booster::RobotBoosterStats s = endpoint.stats(i);
    std::printf(
        "  Booster %d:%d (domain %u): mode %s, %llu states, %llu commands (%llu applied, %llu "
        "ignored, %llu refused, %llu missed), %llu requests (%llu refused, %llu malformed), "
        "%llu images\n",
        w.robot(b.robot).team, w.robot(b.robot).number, b.domain, booster::modeName(s.mode),
        (unsigned long long)s.states_sent, (unsigned long long)s.commands,
        (unsigned long long)s.applied, (unsigned long long)s.ignored,
        (unsigned long long)s.refused, (unsigned long long)s.missed,
        (unsigned long long)s.requests, (unsigned long long)s.requests_refused,
        (unsigned long long)s.requests_malformed, (unsigned long long)s.images);
  }
}

}  // namespace simsoccer::apps

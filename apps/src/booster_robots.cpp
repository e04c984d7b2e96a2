#include "booster_robots.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "cli.hpp"
#include "simsoccer/match/match_session.hpp"

namespace simsoccer::apps {

std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w,
                                          const std::array<int, 2>& team_numbers) {
  std::vector<world::RobotId> out;
  if (!opt.has("booster")) {
    if (opt.has("booster-domain") || opt.flag("booster-lockstep") || opt.flag("booster-netns"))
      throw UsageError(
          "--booster-domain, --booster-lockstep and --booster-netns go with --booster");
    return out;
  }
  const std::string spec = opt.get("booster", "");
  if (spec == "all") {
    for (world::RobotId r = 0; r < w.robotCount(); ++r) out.push_back(r);
    return out;
  }
  std::vector<match::LolaPlayer> players;
  try {
    players = match::parseLolaPlayers(spec);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--booster: ") + e.what());
  }
  for (const match::LolaPlayer& p : players) {
    const std::string item = std::to_string(p.team_number) + ":" + std::to_string(p.player);
    bool found = false;
    for (world::RobotId r = 0; r < w.robotCount(); ++r) {
      const auto& info = w.robot(r);
      if (info.team < 0 || info.team > 1 ||
          team_numbers[static_cast<size_t>(info.team)] != p.team_number || info.number != p.player)
        continue;
      for (world::RobotId seen : out)
        if (seen == r) throw UsageError("--booster: " + item + " is named twice");
      out.push_back(r);
      found = true;
    }
    if (!found)
      throw UsageError("--booster: no robot " + item + " (team numbers " +
                       std::to_string(team_numbers[0]) + " and " + std::to_string(team_numbers[1]) +
                       ")");
  }
  return out;
}

lola::FieldNetwork boosterFieldNetwork() {
  lola::FieldNetwork net;
  net.bridge = "simsoccerk0";  // beside a LoLA match's simsoccer0
  net.prefix = "10.78";
  net.link_prefix = "sk";
  return net;
}

BoosterRobots::~BoosterRobots() {
  endpoint.reset();  // its sockets first, then the namespaces, then the bridge
  namespaces.clear();
  bridge.reset();
}

std::unique_ptr<BoosterRobots> openBoosterRobots(const Options& opt, const world::World& w,
                                                 sim::Simulation& simulation,
                                                 const std::vector<world::RobotId>& robots,
                                                 const std::filesystem::path& dds_config,
                                                 double answer_timeout,
                                                 const std::array<int, 2>& team_numbers) {
  if (robots.empty()) return nullptr;
  auto out = std::make_unique<BoosterRobots>();
  const bool netns = opt.flag("booster-netns");
  const lola::FieldNetwork net = boosterFieldNetwork();
  const auto teamNumber = [&](world::RobotId r) {
    return team_numbers[static_cast<size_t>(std::clamp(w.robot(r).team, 0, 1))];
  };
  if (netns) {
    for (world::RobotId r : robots) net.robotAddress(teamNumber(r), w.robot(r).number);  // throws
    out->bridge = std::make_unique<lola::FieldBridge>(net);
  }
  const auto base = static_cast<uint32_t>(opt.wholeNumber("booster-domain", 0, 0, 230));
  if (base + robots.size() - 1 > 230)
    throw UsageError("--booster-domain: " + std::to_string(robots.size()) + " robots from domain " +
                     std::to_string(base) + " pass domain 230");
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
    if (!netns)
      out->domains.push_back(net::DomainClaim::claim(b.domain, net::DomainTopics::Booster));
    // The robot's own walk for the locomotion service's Walking and Soccer modes, where
    // simsoccer has motions for its model (configs/motions/booster_k1).
    const std::filesystem::path motions =
        findConfig("", "configs/motions/" + w.robot(b.robot).model->name);
    if (std::filesystem::is_directory(motions)) b.motions = motions;
    if (netns) {
      // Its own namespace on the field network (a killed run's is replaced);
      // DDS stays on the namespace's loopback.
      out->namespaces.push_back(std::make_unique<lola::RobotNamespace>(net, teamNumber(b.robot),
                                                                       w.robot(b.robot).number));
      b.network_namespace = out->namespaces.back()->name();
    }
    ec.robots.push_back(b);
  }
  out->endpoint = std::make_unique<booster::Endpoint>(w, ec);
  simulation.addSource(*out->endpoint);
  if (w.scenario().cameras.enabled) out->endpoint->attachCameras(simulation);
  for (const booster::BoosterRobot& b : ec.robots) {
    const auto& info = w.robot(b.robot);
    out->names.push_back(std::to_string(teamNumber(b.robot)) + ":" + std::to_string(info.number));
    if (netns)
      std::printf(
          "Booster SDK: robot %d:%d (%s) as DDS domain 0 in network namespace %s at %s: "
          "simsoccer booster-run --robot %d:%d -- PROGRAM\n",
          teamNumber(b.robot), info.number, info.model->name.c_str(), b.network_namespace.c_str(),
          net.robotAddress(teamNumber(b.robot), info.number).c_str(), teamNumber(b.robot),
          info.number);
    else
      std::printf("Booster SDK: robot %d:%d (%s) on DDS domain %u\n", teamNumber(b.robot),
                  info.number, info.model->name.c_str(), b.domain);
  }
  return out;
}

void printBoosterStats(const BoosterRobots& robots) {
  const booster::Endpoint& endpoint = *robots.endpoint;
  for (size_t i = 0; i < endpoint.config().robots.size(); ++i) {
    const booster::BoosterRobot& b = endpoint.config().robots[i];
    const booster::RobotBoosterStats s = endpoint.stats(i);
    std::printf(
        "  Booster %s (domain %u): mode %s, %llu states, %llu commands (%llu applied, %llu "
        "ignored, %llu refused, %llu missed), %llu requests (%llu refused, %llu malformed), "
        "%llu kicks, %llu kick targets, %llu falls, %llu get-ups, %llu images\n",
        robots.names[i].c_str(), b.domain, booster::modeName(s.mode),
        (unsigned long long)s.states_sent, (unsigned long long)s.commands,
        (unsigned long long)s.applied, (unsigned long long)s.ignored, (unsigned long long)s.refused,
        (unsigned long long)s.missed, (unsigned long long)s.requests,
        (unsigned long long)s.requests_refused, (unsigned long long)s.requests_malformed,
        (unsigned long long)s.kicks, (unsigned long long)s.kick_targets,
        (unsigned long long)s.falls, (unsigned long long)s.get_ups,
        (unsigned long long)s.images);
  }
}

}  // namespace simsoccer::apps

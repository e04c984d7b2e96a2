#include "booster_robots.hpp"

#include <cstdio>
#include <string>

namespace simsoccer::apps {

std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w) {
  std::vector<world::RobotId> out;
  if (!opt.has("booster")) return out;
  const std::string spec = opt.get("booster", "");
  if (spec == "all") {
    for (world::RobotId r = 0; r < w.robotCount(); ++r) out.push_back(r);
    return out;
  }
  size_t start = 0;
  while (start <= spec.size()) {
    const size_t comma = spec.find(',', start);
    const std::string item = spec.substr(start, comma == std::string::npos ? spec.npos : comma - start);
    const size_t colon = item.find(':');
    int team = -1, number = -1;
    try {
      if (colon == std::string::npos) throw std::invalid_argument(item);
      size_t used = 0;
      team = std::stoi(item.substr(0, colon), &used);
      if (used != colon) throw std::invalid_argument(item);
      number = std::stoi(item.substr(colon + 1), &used);
      if (used != item.size() - colon - 1) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--booster: '" + item + "' is not T:P (team 0 or 1, player number) or all");
    }
    bool found = false;
    for (world::RobotId r = 0; r < w.robotCount(); ++r)
      if (w.robot(r).team == team && w.robot(r).number == number) {
        for (world::RobotId seen : out)
          if (seen == r) throw UsageError("--booster: " + item + " is named twice");
        out.push_back(r);
        found = true;
      }
    if (!found) throw UsageError("--booster: the scenario has no robot " + item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

std::unique_ptr<booster::Endpoint> openBoosterRobots(const Options& opt, const world::World& w,
                                                     sim::Simulation& simulation,
                                                     const std::vector<world::RobotId>& robots,
                                                     const std::filesystem::path& dds_config) {
  if (robots.empty()) return nullptr;
  const auto base = static_cast<uint32_t>(opt.wholeNumber("booster-domain", 0, 0, 230));
  if (base + robots.size() - 1 > 230)
    throw UsageError("--booster-domain: " + std::to_string(robots.size()) +
                     " robots from domain " + std::to_string(base) + " pass domain 230");
  booster::EndpointConfig ec;
  ec.dds_config = dds_config;
  ec.lockstep = opt.flag("booster-lockstep");
  if (opt.has("timeout")) ec.answer_timeout = opt.positive("timeout", 0.5);
  for (size_t i = 0; i < robots.size(); ++i)
    ec.robots.push_back({robots[i], base + static_cast<uint32_t>(i), booster::RobotMode::Prepare});
  auto endpoint = std::make_unique<booster::Endpoint>(w, ec);
  simulation.addSource(*endpoint);
  if (w.scenario().cameras.enabled) endpoint->attachCameras(simulation);
  for (const booster::BoosterRobot& b : ec.robots)
    std::printf("Booster SDK: team %d player %d (%s) on DDS domain %u\n", w.robot(b.robot).team,
                w.robot(b.robot).number, w.robot(b.robot).model->name.c_str(), b.domain);
  return endpoint;
}

void printBoosterStats(const booster::Endpoint& endpoint, const world::World& w) {
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

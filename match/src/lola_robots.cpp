#include "simsoccer/match/lola_robots.hpp"

#include <algorithm>
#include <cmath>

namespace simsoccer::match {

std::filesystem::path lolaSocketPath(const std::filesystem::path& out, const LolaPlayer& p) {
  return out / "lola" /
         ("robot_" + std::to_string(p.team_number) + "_" + std::to_string(p.player) + ".sock");
}

LolaRobots::LolaRobots(const MatchSession& session, sim::Simulation& sim,
                       const std::filesystem::path& out, bool lockstep,
                       const std::function<void(const std::string&)>& notice)
    : session_(session) {
  const MatchConfig& c = session.config();
  const auto say = [&](const std::string& line) {
    if (notice) notice(line);
  };
  const auto name = [&](size_t i) {
    return std::to_string(c.lola.robots[i].team_number) + ":" +
           std::to_string(c.lola.robots[i].player);
  };
  // Everything that can fail is made before anything joins `sim`.
  if (c.lola.network) {
    const lola::FieldNetwork net;
    for (const LolaPlayer& p : c.lola.robots) net.robotAddress(p.team_number, p.player);  // throws
    bridge_ = std::make_unique<lola::FieldBridge>(net);
    // With an external GameController it broadcasts to the robots itself
    // (choose this bridge as its network interface) and counts their
    // messages; the simulator only makes the network.
    if (!c.external_gc_port) {
      referee::GameControllerLinkConfig gc;
      gc.address = net.broadcast();
      gc.return_bind = net.hostAddress();
      gc.team_message_bind = net.broadcast();
      gc.team_message_device = net.bridge;
      link_ = std::make_unique<referee::GameControllerLink>(gc);
      link_->update(session.game());  // binds every port now, and sends the first packet
      // The binaries' team messages count against each team's budget.
      team_messages_ = std::make_unique<sim::FieldTeamMessages>(*link_, session.game());
    }
  }
  lola::EndpointConfig ec;
  ec.lockstep = lockstep;
  ec.answer_timeout = c.command_timeout;
  ec.reconnect_timeout = c.lola.reconnect_timeout;
  for (size_t i = 0; i < session.lolaRobots().size(); ++i) {
    lola::RobotSocket rs;
    rs.robot = session.lolaRobots()[i];
    rs.socket = std::filesystem::absolute(lolaSocketPath(out, c.lola.robots[i]));
    const auto own = c.lola.identities.find(name(i));
    rs.identity = own != c.lola.identities.end()
                      ? own->second
                      : lola::defaultIdentity(c.lola.robots[i].team_number,
                                              c.lola.robots[i].player);
    rs.tick_in_battery = c.lola.tick_in_battery;
    ec.robots.push_back(rs);
  }
  endpoint_ = std::make_unique<lola::Endpoint>(session.world(), ec);
  if (session.world().scenario().cameras.enabled) {
    // On a field network the binaries run in namespaces of their own, whose loopback is not
    // this one: the servers listen on the host's address on the bridge, which they reach (and
    // programs on this host too).
    const std::string host = bridge_ ? bridge_->network().hostAddress() : "127.0.0.1";
    std::vector<lola::ImagePorts> ports;
    for (size_t k = 0; k < ec.robots.size(); ++k) {
      const auto top = static_cast<uint16_t>(c.lola.image_port + 2 * k);
      ports.push_back({ec.robots[k].robot, top, static_cast<uint16_t>(top + 1)});
      say("LoLA robot " + name(k) + " images on TCP " + host + " ports " + std::to_string(top) +
          " (top) and " + std::to_string(top + 1) + " (bottom)");
    }
    images_ = std::make_unique<lola::ImageStreams>(sim, ports, host);  // joins sim last of all
  }
  sim.addSource(*endpoint_);
  if (team_messages_) sim.addSource(*team_messages_);
  for (size_t i = 0; i < ec.robots.size(); ++i)
    say("LoLA robot " + name(i) + " at " + ec.robots[i].socket.string());
  if (bridge_) {
    const lola::FieldNetwork& net = bridge_->network();
    say("field network " + net.bridge + ": robots at " + net.prefix +
        ".TEAM.PLAYER (simsoccer lola-run --net), the host at " + net.hostAddress() +
        (link_ ? "; GameController packets to " + net.broadcast() + ":3838, status to " +
                     net.hostAddress() + ":3939"
               : "; the external GameController broadcasts on " + net.bridge));
  }
}

LolaRobots::~LolaRobots() = default;

void LolaRobots::afterPeriod() {
  if (link_) link_->update(session_.game());
}

std::optional<std::array<uint8_t, 9>> LolaRobots::leds(world::RobotId r) const {
  const auto& robots = session_.lolaRobots();
  for (size_t i = 0; i < robots.size(); ++i) {
    if (robots[i] != r) continue;
    const lola::ActuatorValues& v = endpoint_->actuators(i);
    if (!v.leds_set) return std::nullopt;
    const auto byte = [](double x) {
      return static_cast<uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0));
    };
    // An eye is 8 segments: 8 reds, 8 greens, 8 blues; the spectator sees their mean.
    const auto eye = [&](const std::array<float, 24>& e, int channel) {
      double sum = 0.0;
      for (int k = 0; k < 8; ++k) sum += e[static_cast<size_t>(8 * channel + k)];
      return byte(sum / 8.0);
    };
    return std::array<uint8_t, 9>{byte(v.chest[0]), byte(v.chest[1]), byte(v.chest[2]),
                                  eye(v.leye, 0),   eye(v.leye, 1),   eye(v.leye, 2),
                                  eye(v.reye, 0),   eye(v.reye, 1),   eye(v.reye, 2)};
  }
  return std::nullopt;
}

std::vector<LolaResult> LolaRobots::results() const {
  std::vector<LolaResult> out;
  const MatchConfig& c = session_.config();
  const lola::FieldNetwork net;
  for (size_t i = 0; i < c.lola.robots.size(); ++i)
    out.push_back({c.lola.robots[i], endpoint_->config().robots[i].socket, endpoint_->stats(i),
                   link_ ? net.robotAddress(c.lola.robots[i].team_number, c.lola.robots[i].player)
                         : std::string()});
  return out;
}

std::unique_ptr<LolaRobots> openLolaRobots(const MatchSession& session, sim::Simulation& sim,
                                           const std::filesystem::path& out, bool lockstep,
                                           const std::function<void(const std::string&)>& notice) {
  if (session.lolaRobots().empty()) return nullptr;
  return std::make_unique<LolaRobots>(session, sim, out, lockstep, notice);
}

}  // namespace simsoccer::match

#include "serve_report.hpp"

#include <algorithm>
#include <cstdio>

namespace simsoccer::apps {

void printCounters(const world::World& w, const net::SimServer& server) {
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& s = server.stats(r);
    std::printf(
        "  team %d player %d: %s, accepted %llu, rejected %llu, refused %llu, missed %llu\n",
        w.robot(r).team, w.robot(r).number, s.owned ? "owned" : "free",
        (unsigned long long)s.accepted, (unsigned long long)s.rejected,
        (unsigned long long)s.refused, (unsigned long long)s.missed);
  }
}

void printGame(const referee::Game& g) {
  std::printf("game: %s, score %d:%d, %zu referee events\n", referee::stateName(g.state()),
              g.score(0), g.score(1), g.events().size());
  for (const auto& e : g.events())
    std::printf("  %8.2f s  %-12s team %2d player %2d  %s\n", e.time, referee::eventName(e.type),
                e.team, e.player, e.detail.c_str());
}

void printCameraStats(const sim::Simulation& simulation) {
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
}

void printLolaResults(const std::vector<match::LolaResult>& results) {
  for (const match::LolaResult& l : results)
    std::printf(
        "  LoLA %d:%d: %llu sessions, %llu maps, %llu missed, %llu bad maps, %llu refused\n",
        l.player.team_number, l.player.player, (unsigned long long)l.stats.sessions,
        (unsigned long long)l.stats.maps, (unsigned long long)l.stats.missed,
        (unsigned long long)l.stats.bad_maps, (unsigned long long)l.stats.refused);
}

void printGameControllerLink(const referee::GameControllerLink& link) {
  std::printf("GameController packets sent %llu; return packets accepted %llu, rejected %llu\n",
              (unsigned long long)link.packetsSent(), (unsigned long long)link.returnsAccepted(),
              (unsigned long long)link.returnsRejected());
  if (link.returnsRejected() > 0)
    std::printf("last rejected return packet: %s\n", link.lastReturnError().c_str());
}

void printFinalState(const world::World& w) {
  const engine::Vec3 ball = w.ballState().pose.translation();
  std::printf("final state hash %016llx, the ball at (%.2f, %.2f) m\n",
              static_cast<unsigned long long>(w.stateHash()), ball.x(), ball.y());
}

}  // namespace simsoccer::apps

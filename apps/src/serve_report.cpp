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

}  // namespace simsoccer::apps

// simsoccer replay: what a match log holds, its video, and a re-run of the
// game through the same period pipeline with the recorded commands.
#include <cstdio>
#include <optional>

#include "cli.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/match/outputs.hpp"
#include "simsoccer/sim/log_source.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {
namespace {

const char* kReplayHelp =
    "usage: simsoccer replay LOG [--video FILE] [--from T] [--to T] [--physics [--threads N]\n"
    "                            [--touches]] [--events]\n"
    "\n"
    "Reads a match log: prints what it holds (--events: every referee event); --video renders the "
    "spectator camera over\n"
    "[--from, --to] s (default the whole log) to FILE (.mp4 or .avi; .png: one still at\n"
    "--from); --physics re-runs the\n"
    "game through the physics and the referee with the recorded commands and checks every\n"
    "period's state hash against the log (exit status 1 on the first difference); --threads:\n"
    "with N solver threads instead of the scenario's (the hashes must not change); --touches:\n"
    "every touch of the ball in [--from, --to] s as the re-run finds it (who, with which link,\n"
    "where the ball was), as the referee judges who touched it last. A log cut\n"
    "inside a block (its writer was killed) is read up to the cut, with a warning and exit\n"
    "status 4.\n";

}  // namespace

int replay(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "physics", "events", "touches"},
                    {"video", "from", "to", "threads"});
  if (opt.help(kReplayHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one match log");
  const std::filesystem::path file = opt.positional()[0];
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw UsageError(file.string() + ": is a folder");
  const double from = opt.nonNegative("from", 0.0), to = opt.nonNegative("to", 1e12);
  if (to < from) throw UsageError("--to must not be before --from");
  if (opt.has("video")) {
    const std::string ext = std::filesystem::path(opt.get("video", "")).extension().string();
    if (ext != ".mp4" && ext != ".avi" && ext != ".png")  // as renderVideo tells them apart
      throw UsageError("--video " + opt.get("video", "") + ": .mp4, .avi or .png");
    opt.checkWritable("video");
  }
  const int threads = opt.wholeNumber("threads", 0, 1, world::PhysicsConfig::kMaxThreads);
  if (opt.has("threads") && !opt.flag("physics"))
    throw UsageError("--threads goes with --physics (the solver threads of the re-run)");
  if (opt.flag("touches") && !opt.flag("physics"))
    throw UsageError("--touches goes with --physics (the touches are the re-run's contacts)");
  world::MatchLogReader reader(file);
  const auto& h = reader.header().values;
  int frames = 0;
  double first_time = -1, last_time = 0;
  std::vector<world::LogFrame> all;
  world::LogFrame f;
  int events = 0;
  while (reader.next(f)) {
    if (first_time < 0) first_time = f.time;
    last_time = f.time;
    events += static_cast<int>(f.events.size());
    if (opt.flag("events"))
      for (const auto& e : f.events)
        std::printf("  %8.2f s  %-12s team %2d player %2d  %s\n", e.time, e.type.c_str(), e.team,
                    e.player, e.detail.c_str());
    ++frames;
  }
  std::printf("%s: %d frames (%.2f .. %.2f s), %zu robots, %d referee events, seed %s, config %s\n",
              file.string().c_str(), frames, first_time, last_time, reader.header().robots.size(),
              events, h.count("seed") ? h.at("seed").c_str() : "?",
              h.count("config") ? h.at("config").c_str() : "?");
  int status = 0;
  // A log cut inside a block (its writer was killed) says so, and replay's
  // exit status says the game is not all there.
  if (const auto cut = reader.truncatedAt()) {
    std::printf(
        "warning: the log is cut inside the block at byte %llu: the frames after %.2f s "
        "are lost\n",
        static_cast<unsigned long long>(*cut), last_time);
    status = 4;
  }
  if (opt.has("video") && (frames == 0 || from > last_time || to < first_time))
    throw UsageError("--from " + fmt(from, 2) + " --to " + (opt.has("to") ? fmt(to, 2) : "(end)") +
                     ": the log holds " + fmt(first_time, 2) + " .. " + fmt(last_time, 2) + " s");
  if (opt.flag("physics")) {
    if (!h.count("config")) throw std::runtime_error(file.string() + ": no config in the header");
    match::MatchConfig config = match::loadMatchConfig(h.at("config"));
    if (h.count("config_hash") && h.at("config_hash") != config.hash)
      std::printf("warning: %s changed since the log was written\n", config.file.c_str());
    if (h.count("half_duration")) config.half_duration = std::stod(h.at("half_duration"));
    const uint64_t seed = std::stoull(h.at("seed"));
    match::MatchSession session(config, seed, threads);
    // The recorded commands are what each period applied: replayed serially
    // through the same pipeline (and gate) as the game, whatever its mode.
    sim::Simulation simulation(session.world());
    session.attach(simulation);
    sim::LogSource recorded(file);
    simulation.addSource(recorded);
    int checked = 0;
    const world::World& world = session.world();
    // Every touch the match records count (match::BallTouchCounter), as the re-run finds it.
    match::BallTouchCounter touches(world.scenario().physics.dt);
    auto printTouch = [&] {
      const auto touch = touches.next(world.lastBallTouch());
      if (!opt.flag("touches") || !touch) return;
      const double at = static_cast<double>(touch->step) * world.scenario().physics.dt;
      if (at < from || at > to) return;
      const world::RobotInfo& r = world.robot(touch->robot);
      const engine::RigidBodyState ball_state = world.ballState();
      const auto& ball = ball_state.pose.translation();
      std::printf("  %8.2f s  touch  team %d player %d  %-16s  ball at %.2f %.2f m\n", at, r.team,
                  r.number, r.model->body->links.at(static_cast<size_t>(touch->link)).name.c_str(),
                  ball.x(), ball.y());
    };
    // Period after period as long as the log has one and every hash agrees.
    sim::RunLoop(simulation, sim::Pacing::Lockstep)
        .run([&] { return (status != 0 && status != 4) || !recorded.next(); }, -1,
             [&] {
               if (session.world().stateHash() != recorded.frame().state_hash) {
                 std::printf("state hash differs at %.2f s (frame %d)\n", recorded.frame().time,
                             checked + 1);
                 status = 1;
                 return;
               }
               printTouch();
               ++checked;
             });
    if (recorded.refused() > 0)
      std::printf("warning: %llu recorded commands refused (not finite or out of range)\n",
                  static_cast<unsigned long long>(recorded.refused()));
    if (status == 0 || status == 4)
      std::printf("physics replay: %d of %d periods, every state hash equal\n", checked, frames);
  }
  if (opt.has("video")) {
    match::VideoSettings v;
    if (h.count("config")) {
      try {
        v = match::loadMatchConfig(h.at("config")).video;
      } catch (const std::exception&) {
      }
    }
    const auto r = match::renderVideo(file, opt.get("video", ""), v, from, to);
    std::printf("video: %s, %d frames\n", r.file.string().c_str(), r.frames);
  }
  return status;
}

}  // namespace simsoccer::apps

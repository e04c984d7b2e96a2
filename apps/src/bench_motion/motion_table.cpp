// The table of `simsoccer bench motion`: every trial, seeded, against its
// target.
#include "motion_table.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "cli.hpp"

namespace simsoccer::apps::motion {

int printMotionTable(const TrialContext& c, const Options& opt, uint64_t seed) {
  TrialContext quiet = c;  // the table's trials print no traces
  quiet.verbose = false;
  const double random_minutes = opt.number("random-minutes", 10.0);
  const MotionBench& b = c.bench;
  std::printf(
      "simsoccer bench motion: one %s on an empty field (%s), walk engine (%.0f ms steps), "
      "joint targets only, %s periods\n",
      b.robot.c_str(), b.field.filename().string().c_str(), c.walk.step_period * 1e3,
      sim::modeName(c.mode));
  std::fflush(stdout);
  Table table;
  table.header = {"robots", "test",          "commanded", "achieved",
                  "unit",   "deviation_pct", "falls",     "sim_seconds"};
  auto row = [&](const std::string& test, double commanded, double achieved, const char* unit,
                 double deviation, int falls, double seconds) {
    table.rows.push_back({"1", test, fmt(commanded, 3), fmt(achieved, 3), unit, fmt(deviation, 1),
                          std::to_string(falls), fmt(seconds, 0)});
    std::fprintf(stderr, "  %s done\n", test.c_str());
  };
  {
    const double v = b.walk_forward, seconds = std::ceil(5.0 / v) + 2.0;  // 5 m and more
    const WalkResult r = walkTrial(
        quiet, [&](double) { return Eigen::Vector3d(v, 0, 0); }, seconds);
    row("walk_forward", v, r.speed, "m/s", 100.0 * std::abs(r.lateral) / std::max(r.distance, 1e-9),
        r.fell, seconds);
  }
  {
    const double v = b.walk_sideways, seconds = 10.0;
    const WalkResult r = walkTrial(
        quiet, [&](double) { return Eigen::Vector3d(0, v, 0); }, seconds);
    row("walk_sideways", v, r.speed, "m/s",
        100.0 * std::abs(r.lateral) / std::max(r.distance, 1e-9), r.fell, seconds);
  }
  {
    const double w = b.turn, seconds = 5.0;
    const WalkResult r = walkTrial(
        quiet, [&](double) { return Eigen::Vector3d(0, 0, w); }, seconds);
    const double turned = r.turned;
    row("turn", w * 180 / M_PI, turned / seconds * 180 / M_PI, "deg/s",
        100.0 * std::abs(turned - w * seconds) / (w * seconds), r.fell, seconds);
  }
  {
    // 20 kicks, 10 with each foot, the ball up to 2 cm either side of the
    // foot's middle (seeded); a success: the target distance (a Nao 3 m, a K1 4 m) within 15
    // degrees of straight.
    std::mt19937_64 rng(seed + 100);
    double sum = 0, worst_angle = 0;
    int ok = 0, falls = 0;
    for (int i = 0; i < 20; ++i) {
      const double offset = -0.02 + 0.04 * static_cast<double>(rng() >> 11) * 0x1.0p-53;
      const KickResult k = kickTrial(quiet, i % 2 ? agents::Leg::Left : agents::Leg::Right, offset,
                                     seed + static_cast<uint64_t>(i));
      sum += k.distance;
      worst_angle = std::max(worst_angle, std::abs(k.direction));
      ok += k.distance >= b.kick_distance && std::abs(k.direction) <= 15 * M_PI / 180;
      falls += k.fell;
    }
    row("kick_distance", b.kick_distance, sum / 20, "m", worst_angle * 180 / M_PI, falls, 20 * 9.0);
    row("kick_success", 0.9, ok / 20.0, "share", 0, falls, 20 * 9.0);
  }
  {
    // Get-up: N trials from each side (seeded heading, spot, tilt); success:
    // standing in the stance within 12 s of lying still.
    const int trials = static_cast<int>(opt.number("get-up-trials", 20));
    for (const bool front : {true, false}) {
      int ok = 0;
      double worst = 0.0;
      for (int i = 0; i < trials; ++i) {
        const GetUpResult g = getUpTrial(quiet, front, seed + 200 + static_cast<uint64_t>(i));
        ok += g.success && g.seconds < 8.0;
        worst = std::max(worst, g.success ? g.seconds : 12.0);
      }
      row(front ? "get_up_front" : "get_up_back", 0.95, ok / std::max(1.0, double(trials)), "share",
          worst, 0, trials * 13.0);
    }
  }
  {
    // Sit down (after walking) and stand up again: N seeded trials.
    const int trials = static_cast<int>(opt.number("sit-trials", 20));
    int ok = 0, falls = 0;
    double slowest = 0.0, highest = 0.0;
    for (int i = 0; i < trials; ++i) {
      const SitResult t = sitTrial(quiet, seed + 250 + static_cast<uint64_t>(i));
      ok += t.success;
      falls += t.falls;
      slowest = std::max(slowest, t.up_seconds < 0 ? 5.0 : t.up_seconds);
      highest = std::max(highest, t.seated_height);
    }
    std::fprintf(stderr, "  sit: seated torso at most %.3f m, back in the stance within %.2f s\n",
                 highest, slowest);
    row("sit_and_stand", 0, ok / std::max(1.0, double(trials)), "share", slowest, falls,
        trials * 12.0);
  }
  {
    // The striker alone: N seeded trials from random spots, 60 s each to score.
    const int trials = static_cast<int>(opt.number("striker-trials", 20));
    int scored = 0, falls = 0;
    std::vector<double> times;
    for (int i = 0; i < trials; ++i) {
      const StrikerResult s = strikerTrial(quiet, seed + 300 + static_cast<uint64_t>(i), 60.0);
      scored += s.scored;
      falls += s.falls;
      if (s.scored) times.push_back(s.seconds);
    }
    std::sort(times.begin(), times.end());
    const double median = times.empty() ? 0.0 : times[times.size() / 2];
    row("striker_scores", 0.8, scored / std::max(1.0, double(trials)), "share", median, falls,
        trials * 60.0);
  }
  {
    // Penalty kicks against the behaviour goalkeeper: N seeded trials.
    const int trials = static_cast<int>(opt.number("penalty-trials", 50));
    std::array<int, 4> count{};
    for (int i = 0; i < trials; ++i)
      ++count[static_cast<size_t>(
          penaltyTrial(quiet, seed + 500 + static_cast<uint64_t>(i), 30.0))];
    std::fprintf(stderr, "  penalties:");
    for (size_t k = 0; k < count.size(); ++k)
      std::fprintf(stderr, " %d %s", count[k], penaltyOutcomeName(static_cast<PenaltyOutcome>(k)));
    std::fprintf(stderr, "\n");
    const auto share = [&](PenaltyOutcome o) {
      return count[static_cast<size_t>(o)] / std::max(1.0, double(trials));
    };
    row("penalty_scoring", 0, share(PenaltyOutcome::Goal), "share",
        100.0 * share(PenaltyOutcome::Saved), 0, trials * 30.0);
  }
  {
    // The goalkeeper against balls rolled at its goal (seeded): in play (it
    // blocks) and in the shoot-out (it also dives); the share kept out.
    const int trials = static_cast<int>(opt.number("block-trials", 20));
    for (const bool shootout : {false, true}) {
      int saved = 0, in_reach = 0, saved_in_reach = 0, blocks = 0, falls = 0;
      for (int i = 0; i < trials; ++i) {
        const BlockResult b = blockTrial(quiet, seed + 700 + static_cast<uint64_t>(i), shootout);
        saved += b.saved;
        in_reach += b.in_reach;
        saved_in_reach += b.saved && b.in_reach;
        blocks += b.blocks;
        falls += b.falls;
      }
      std::fprintf(stderr, "  %s: %d blocks/dives, %d of %d balls within reach saved\n",
                   shootout ? "shoot-out keeper" : "keeper", blocks, saved_in_reach, in_reach);
      row(shootout ? "shootout_keeper_saves" : "keeper_saves", 0,
          saved / std::max(1.0, double(trials)), "share",
          100.0 * saved_in_reach / std::max(1, in_reach), falls, trials * 6.0);
    }
  }
  {
    const double seconds = random_minutes * 60.0;
    row("random_commands", 0, 0, "-", 0, randomCommandsTrial(c, seed, seconds), seconds);
    // Its own commands: seeded apart from random_commands' (seed + 900).
    constexpr uint64_t kStopAndGoSeed = 900;
    row("stop_and_go", 0, 0, "-", 0,
        randomCommandsTrial(c, seed + kStopAndGoSeed, seconds, 0.5, 0.3), seconds);
  }
  table.finish(
      "walk_forward: the commanded speed for 5 m / speed + 2 s, achieved = torso displacement / "
      "time (the speed ramp included), deviation = sideways drift / distance; walk_sideways "
      "likewise for 10 s; turn: for 5 s (at most 5 rad); kick_distance: mean ball travel of 20 "
      "kicks (10 per foot, the ball up to 2 cm sideways of the foot's middle), deviation = the "
      "largest angle off straight (deg); kick_success: share of kicks >= the commanded distance "
      "within 15 deg; get_up_front / "
      "get_up_back: share of trials (robot dropped on its front / back, seeded) standing in the "
      "stance within 8 s, deviation column = the slowest trial's seconds (12: failed); "
      "sit_and_stand: share of trials (2 s walking at a seeded velocity, 5 s sitting, 5 s "
      "standing) on its feet throughout with the torso >= 5 cm lower seated and back in the "
      "stance, deviation column = the slowest stand-up's seconds; "
      "striker_scores: share of trials (robot and ball at seeded random spots, the striker "
      "behaviour alone) that score within 60 s, deviation column = the median seconds to score; "
      "penalty_scoring: share of penalty kicks (kicker behaviour against the goalkeeper "
      "behaviour, seeded) that score, deviation column = % saved; keeper_saves / "
      "shootout_keeper_saves: share of balls rolled at the goal (seeded, 1.6-2.4 m/s from 2.5 m, "
      "aimed inside the posts) the goalkeeper behaviour keeps out in play (it blocks) / in the "
      "shoot-out (it also dives), deviation column = % of those aimed within its reach "
      "(block_reach / dive_reach of the agent config from its middle), falls = falls "
      "besides dives; "
      "random_commands: a new "
      "random velocity every 2 s on an empty field, falls counted (the robot is put back up "
      "after each); stop_and_go: likewise, a new command every 0.5 s, 3 in 10 of them "
      "\"stand\" (stops and starts, as a behaviour positioning near its target).",
      opt.get("csv", ""));
  return 0;
}

}  // namespace simsoccer::apps::motion

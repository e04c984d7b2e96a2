// simsoccer bench motion's one-trial modes, for tuning: one get-up, striker, block, penalty,
// kick, random walk or walk at a command, chosen by the options, its result on one line.
#include <cmath>
#include <cstdio>

#include "motion_table.hpp"

namespace simsoccer::apps::motion {

std::optional<int> runSingleTrial(const TrialContext& c, const Options& opt, uint64_t seed) {
  if (opt.has("get-up")) {  // one get-up, for tuning
    const std::string side = opt.get("get-up", "");
    if (side != "front" && side != "back") throw UsageError("--get-up must be front or back");
    const GetUpResult r = getUpTrial(c, side == "front", seed, opt.get("snapshots", ""));
    std::printf("get-up from the %s: %s in %.2f s, %d attempts\n", side.c_str(),
                r.success ? "standing" : "FAILED", r.seconds, r.attempts);
    return 0;
  }
  if (opt.flag("striker")) {  // one striker trial, for tuning
    const StrikerResult r = strikerTrial(c, seed, 60.0);
    std::printf("striker: %s in %.1f s, %d falls\n", r.scored ? "scored" : "no goal", r.seconds,
                r.falls);
    return 0;
  }
  if (opt.flag("block")) {  // one ball at the goalkeeper, for tuning
    BlockShot shot;
    if (opt.has("ball-offset")) shot.offset = opt.number("ball-offset", 0.0);
    if (opt.has("ball-speed")) shot.speed = opt.number("ball-speed", 2.0);
    const BlockResult r = blockTrial(c, seed, opt.flag("shootout"), shot);
    std::printf("block: %s (%s), %d blocks/dives, %d falls\n", r.saved ? "saved" : "not saved",
                r.in_reach ? "in reach" : "out of reach", r.blocks, r.falls);
    return 0;
  }
  if (opt.flag("penalty")) {  // one penalty, for tuning
    std::printf("penalty: %s\n", penaltyOutcomeName(penaltyTrial(c, seed, 30.0)));
    return 0;
  }
  if (opt.flag("kick")) {  // one kick, for tuning
    const KickResult r =
        kickTrial(c, opt.number("foot", 1) == 0 ? agents::Leg::Left : agents::Leg::Right,
                  opt.number("ball-offset", 0), 1, opt.number("ball-gap", 0.015),
                  static_cast<int>(opt.number("steps-first", 0)));
    std::printf("ball %.3f m at %.1f deg, fell %d\n", r.distance, r.direction * 180 / M_PI, r.fell);
    return 0;
  }
  if (opt.flag("random")) {  // the random-commands trial alone, for tuning
    const double seconds = opt.number("random-minutes", 10.0) * 60.0;
    const double hold = opt.number("command-seconds", 2.0),
                 stand_share = opt.number("stand-share", 0.0);
    if (!(hold >= 0.01)) throw UsageError("--command-seconds: at least 0.01 s");
    if (!(stand_share >= 0.0 && stand_share <= 1.0))
      throw UsageError("--stand-share: a share from 0 to 1");
    std::printf("random commands: %d falls in %.0f s\n",
                randomCommandsTrial(c, seed, seconds, hold, stand_share), seconds);
    return 0;
  }
  if (opt.has("vx") || opt.has("vy") || opt.has("turn")) {  // one walk, for tuning
    const Eigen::Vector3d v(opt.number("vx", 0), opt.number("vy", 0), opt.number("turn", 0));
    const WalkResult r = walkTrial(
        c, [&](double) { return v; }, opt.number("seconds", 10.0));
    std::printf(
        "distance %.3f m, speed %.3f m/s, lateral %.3f m, turned %.3f rad, fell %d at %.2f\n",
        r.distance, r.speed, r.lateral, r.turned, r.fell, r.fell_at);
    return 0;
  }
  return std::nullopt;
}

}  // namespace simsoccer::apps::motion

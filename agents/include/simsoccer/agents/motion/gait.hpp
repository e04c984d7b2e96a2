// A robot's gait as data: the walk's and the kick's parameters, read from
// `gait.yaml` in the robot's motions folder (configs/motions/booster_k1/);
// the code's defaults are the Nao's (configs/motions/ has no gait file).
#pragma once

#include <filesystem>

#include "simsoccer/agents/motion/kick_engine.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"

namespace simsoccer::agents {

struct Gait {
  WalkParameters walk;
  KickParameters kick;
};

// Reads `walk:` and `kick:`, maps of the parameters by their names in
// WalkParameters and KickParameters; a parameter not named keeps its
// default. Throws engine::ConfigError (file, key, reason) on an unknown or
// bad one.
Gait loadGait(const std::filesystem::path& file);
// `motions_dir`/gait.yaml where it exists, else the defaults.
Gait loadGaitIn(const std::filesystem::path& motions_dir);
// The ranges loadGait holds a file to, for parameters set otherwise (bench motion's tuning
// options): throws std::invalid_argument naming the first one out of range ("walk.max_forward:
// must be > 0").
void checkGait(const Gait& gait);

}  // namespace simsoccer::agents

// simsoccer bench motion: the agents' motion on an empty field, in this
// process on the real physics, through the same period pipeline as a match.
// The options; the trials are one file each, the table is motion_table.cpp, the one-trial
// modes single_trial.cpp.
#include <cstdio>

#include "cli.hpp"
#include "motion_table.hpp"
#include "simsoccer/agents/motion/gait.hpp"
#include "trial.hpp"

namespace simsoccer::apps {
namespace {

const char* kBenchMotionHelp =
    "usage: simsoccer bench motion [--robot R] [--random-minutes M] [--seed N] [--csv FILE]\n"
    "       simsoccer bench motion --vx V [--vy V] [--turn W] [--seconds S] [--verbose]\n"
    "\n"
    "One robot on an empty field, driven by the walk engine at the control rate through\n"
    "joint targets only (the agents' motion, in this process). Per test: commanded and achieved\n"
    "speed, path deviation, falls: forward over 5 m, sideways, turning, and M minutes (default\n"
    "10) of random velocity commands; kicks, get-ups, the behaviours.\n"
    "  --robot R     nao_v6_h25 (default: a Nao on the SPL field, forward 0.25 m/s) or\n"
    "                booster_k1 (on the HSL M-Field, forward 0.5 m/s): "
    "configs/bench/motion_R.yaml\n"
    "                names the robot, field, motions, agent config and targets\n"
    "  --bench FILE  another such file\n"
    "With --vx/--vy/--turn: one walk at that command; with --kick [--foot 0|1] [--ball-offset M] "
    "[--ball-gap M] [--steps-first N]:\n"
    "one kick (from the stance the feet stand in, the ball in front of where the kicking foot\n"
    "swings: beside the support foot in the gait's stance); both for tuning, with any parameter\n"
    "of agents::WalkParameters / KickParameters by name (--sway, --lift, --period,\n"
    "--torso-offset, --height, --ankle-pitch-gyro, --ankle-roll-gyro, --gyro-smoothing,\n"
    "--forward-scale, --max-forward, --max-turn, --max-turn-accel, --max-turn-on-spot,\n"
    "--max-turn-accel-on-spot, --lean, --hip-roll, --heading-gain, --start-shift-time,\n"
    "--kick-reach, --kick-swing, --kick-shift, --kick-lift,\n"
    "--kick-draw-back, --kick-hip-roll, --kick-swing-height, --kick-swing-out,\n"
    "--kick-ready-time, --kick-tilt-gain, --kick-tilt-deadband).\n"
    "With --get-up front|back [--seed N] [--verbose]: one get-up trial.\n"
    "With --random [--random-minutes M] [--command-seconds S] [--stand-share P] [--seed N]\n"
    "[--verbose]: the random-commands trial alone, a new command every S s (default 2), a\n"
    "share P of them \"stand\" (default 0; the table's stop_and_go: --command-seconds 0.5\n"
    "--stand-share 0.3).\n"
    "With --striker or --penalty [--seed N] [--verbose]: one striker / penalty trial.\n"
    "With --block [--shootout] [--seed N] [--ball-offset M] [--ball-speed V] [--verbose]: one "
    "ball\n"
    "rolled at the goalkeeper (in play: it blocks; in the shoot-out: it also dives), passing its\n"
    "line M m left of its middle, V m/s (default: seeded, anywhere inside the posts, 1.6-2.4).\n"
    "  --get-up-trials N, --sit-trials N  get-up trials per side, sit trials, in the table\n"
    "                (default 20, 20)\n"
    "  --motions DIR the motions from DIR (default: the bench file's; for tuning them): all of\n"
    "                get_up_front, get_up_back, block, dive_left, dive_right, sit_down, stand_up,\n"
    "                and the gait (gait.yaml) where there is one\n"
    "  --snapshots F.png  with --get-up: the robot seen from its side every 0.2 s (the first\n"
    "                7.2 s), tiled\n"
    "  --striker-trials N, --penalty-trials N, --block-trials N  trials in the table (default\n"
    "                20, 50, 20)\n"
    "  --mode M      the control period: serial or pipelined (one period of actuation delay,\n"
    "                as in a match of that mode); default: the matches' (%s)\n"
    "  --dt S, --control-period S  the physics step and control period (default 0.010 and\n"
    "                0.010; a LoLA match runs 0.006 and 0.012)\n"
    "  --joint-sweeps N  sweeps over the joint rows per solver iteration (default 2; a 5 ms\n"
    "                step needs 1: docs/models.md)\n"
    "  --csv FILE    also write the table as CSV\n";

}  // namespace

int benchMotion(int argc, char** argv, int first) {
  // Tuning knobs: the walk's and the kick's parameters by name.
  agents::WalkParameters wp;
  agents::KickParameters kp;
  const std::vector<std::pair<std::string, double*>> knobs{
      {"sway", &wp.sway},
      {"lift", &wp.foot_lift},
      {"period", &wp.step_period},
      {"torso-offset", &wp.torso_offset},
      {"height", &wp.ankle_height},
      {"ankle-pitch-gyro", &wp.ankle_pitch_gyro},
      {"ankle-roll-gyro", &wp.ankle_roll_gyro},
      {"gyro-smoothing", &wp.gyro_smoothing},
      {"forward-scale", &wp.forward_scale},
      {"max-forward", &wp.max_forward},
      {"max-turn", &wp.max_turn},
      {"max-turn-accel", &wp.max_turn_accel},
      {"max-turn-on-spot", &wp.max_turn_on_spot},
      {"max-turn-accel-on-spot", &wp.max_turn_accel_on_spot},
      {"lean", &wp.torso_lean},
      {"hip-roll", &wp.hip_roll_compensation},
      {"heading-gain", &wp.heading_gain},
      {"start-shift-time", &wp.start_shift_time},
      {"support-lean", &wp.support_lean},
      {"max-support-hold", &wp.max_support_hold},
      {"kick-reach", &kp.reach},
      {"kick-swing", &kp.swing_time},
      {"kick-shift", &kp.shift},
      {"kick-lift", &kp.lift},
      {"kick-draw-back", &kp.draw_back},
      {"kick-hip-roll", &kp.hip_roll_compensation},
      {"kick-swing-height", &kp.swing_height},
      {"kick-swing-out", &kp.swing_out},
      {"kick-ready-time", &kp.ready_time},
      {"kick-tilt-gain", &kp.tilt_gain},
      {"kick-tilt-deadband", &kp.tilt_deadband}};
  std::vector<std::string> valued{"robot",
                                  "bench",
                                  "seconds",
                                  "csv",
                                  "vx",
                                  "vy",
                                  "turn",
                                  "random-minutes",
                                  "command-seconds",
                                  "stand-share",
                                  "seed",
                                  "foot",
                                  "ball-offset",
                                  "ball-gap",
                                  "ball-speed",
                                  "steps-first",
                                  "get-up",
                                  "get-up-trials",
                                  "sit-trials",
                                  "striker-trials",
                                  "penalty-trials",
                                  "motions",
                                  "snapshots",
                                  "block-trials",
                                  "mode",
                                  "dt",
                                  "control-period",
                                  "joint-sweeps"};
  for (const auto& k : knobs) valued.push_back(k.first);
  const Options opt(
      argc, argv, first,
      {"help", "verbose", "kick", "striker", "penalty", "block", "shootout", "random"}, valued);
  char help[8192];
  std::snprintf(help, sizeof help, kBenchMotionHelp, sim::modeName(sim::kDefaultMode));
  if (opt.help(help)) return 0;
  opt.noPositional();
  motion::TrialContext c;
  if (opt.has("robot") && opt.has("bench"))
    throw UsageError("--robot and --bench exclude each other");
  const std::string robot = opt.get("robot", "nao_v6_h25");
  const std::filesystem::path bench_file =
      opt.has("bench") ? std::filesystem::path(opt.get("bench", ""))
                       : findConfig("", "configs/bench/motion_" + robot + ".yaml");
  if (!std::filesystem::exists(bench_file))
    throw UsageError(opt.has("bench")
                         ? "--bench: no such file " + bench_file.string()
                         : "--robot " + robot + ": no " + bench_file.string() +
                               " (robots with a motion bench: nao_v6_h25, booster_k1)");
  c.bench = motion::loadMotionBench(bench_file);
  // Another motions folder (same file names) for tuning get-up motions.
  if (opt.has("motions") && !std::filesystem::is_directory(opt.get("motions", "")))
    throw UsageError("--motions: no such folder: " + opt.get("motions", ""));
  c.motions_dir = opt.has("motions") ? opt.get("motions", "") : c.bench.motions.string();
  // The robot's gait, then any knob given.
  const agents::Gait gait = agents::loadGaitIn(c.motions_dir);
  wp = gait.walk;
  kp = gait.kick;
  for (const auto& [name, value] : knobs) *value = opt.number(name, *value);
  try {
    agents::checkGait({wp, kp});
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("the gait with the tuning options given: ") + e.what());
  }
  c.walk = wp;
  c.kick = kp;
  c.verbose = opt.flag("verbose");
  try {
    c.mode = sim::parseMode(opt.get("mode", sim::modeName(sim::kDefaultMode)));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--mode: ") + e.what());
  }
  c.dt = opt.positive("dt", 0.0);  // 0: the bench file's
  c.control_period = opt.positive("control-period", 0.0);
  // The trials' counts and lengths, refused before any trial runs.
  for (const char* n :
       {"get-up-trials", "sit-trials", "striker-trials", "penalty-trials", "block-trials"})
    (void)opt.wholeNumber(n, 0, 0, 100000);
  (void)opt.nonNegative("random-minutes", 0.0);
  (void)opt.positive("seconds", 0.0);
  (void)opt.wholeNumber("foot", 0, 0, 1);
  (void)opt.wholeNumber("steps-first", 0, 0, 1000);
  c.joint_sweeps = opt.wholeNumber("joint-sweeps", 0, 1, 16);
  const auto seed = opt.seed("seed", 1);
  if (const std::optional<int> status = motion::runSingleTrial(c, opt, seed)) return *status;
  return motion::printMotionTable(c, opt, seed);
}

}  // namespace simsoccer::apps

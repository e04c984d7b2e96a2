// bench motion's trials: one robot (or a striker and a keeper) on an empty
// field (a Nao on the SPL field, a K1 on the HSL M-Field), driven through the same period pipeline
// as a match (the gate, the quantisation and the mode's actuation timing), one file per trial.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/agents/motion/kick_engine.hpp"
#include "simsoccer/agents/motion/leg_kinematics.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/match/inprocess_agents.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps::motion {

using engine::Vec3;

// What bench motion runs for one robot, from configs/bench/motion_<robot>.yaml:
// the robot, its field, its motions (keyframes and gait) and agent config,
// and the table's targets.
struct MotionBench {
  std::string robot;  // the robot's name (its model's)
  std::filesystem::path robot_model, field, motions, agents;
  double walk_forward = 0.25, walk_sideways = 0.1, turn = 0.8;  // m/s, m/s, rad/s
  double kick_distance = 3.0;                                   // m, a successful kick
  // The random walk's commands: [lowest, highest] forward, sideways (m/s), turn (rad/s).
  std::array<double, 2> random_forward{-0.1, 0.3}, random_sideways{-0.1, 0.1},
      random_turn{-0.8, 0.8};
};
// Throws engine::ConfigError naming the file, key and reason.
MotionBench loadMotionBench(const std::filesystem::path& file);

// What every trial shares: the robot's bench, the period mode, the motions, the tuning knobs.
struct TrialContext {
  MotionBench bench;
  sim::Mode mode = sim::kDefaultMode;
  std::string motions_dir;  // configs/motions, or another folder for tuning
  agents::WalkParameters walk;
  agents::KickParameters kick;
  bool verbose = false;  // a trace on stderr, for tuning
  // The physics step and control period (0: emptyField's 5 ms and 10 ms);
  // 3 ms and 12 ms are a LoLA match's.
  double dt = 0.0, control_period = 0.0;
  int joint_sweeps = 0;  // 0: the scenario's
};

// The bench's robot at (-3, 0) facing +x on its empty field, the ball out of the way.
world::Scenario emptyField(const TrialContext& c);

// Robot 0 driven by code in this process: at each period's observe stage,
// `control` computes the robot's command (actuator order) from the state of
// the tick; false: no new command (the last one holds).
class DriverSource : public sim::CommandSource {
 public:
  using Control = std::function<bool(const world::World&, std::span<float> position,
                                     std::span<float> stiffness)>;
  void setControl(Control control) { control_ = std::move(control); }
  void observe(const sim::Observation& o) override;
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override;

 private:
  Control control_;
  bool has_ = false;
  std::vector<float> position_ = std::vector<float>(world::kActuators),
                     stiffness_ = std::vector<float>(world::kActuators);
};

// A trial's world and its period pipeline, with robot 0's driver or the
// built-in agents in this process.
struct TrialWorld {
  TrialWorld(const world::Scenario& scenario, const TrialContext& context);
  // The built-in agents drive the robots instead of the driver.
  void addAgents(std::vector<agents::Role> roles, uint64_t seed);
  void period() { simulation.period(); }
  double dt() const { return world.scenario().physics.control_period; }

  world::World world;
  sim::Simulation simulation;
  DriverSource driver;
  std::unique_ptr<match::InProcessAgents> agents;

 private:
  TrialContext context_;
};

// Body joint targets as robot 0's command in actuator order at one stiffness
// (a mimic joint follows its master; hands at stiffness 0).
void bodyTargetsToCommand(const robots::RobotModel& model, const std::vector<double>& targets,
                          double stiffness, std::span<float> position,
                          std::span<float> stiffness_out);

// One control period of the walk on robot 0: updated from its sensor frame (gyro, IMU yaw),
// its targets (body joint order) written as the command at full stiffness.
void walkPeriod(const world::World& world, agents::WalkEngine& engine, double dt,
                std::vector<double>& targets, std::span<float> position,
                std::span<float> stiffness);

// Robot 0 for 1 s from the stand pose into the walk's stance (eased in,
// then held); `targets` (body joint order) end in the stance.
void settleIntoStance(TrialWorld& t, agents::WalkEngine& engine, std::vector<double>& targets);

// The goal the ball is in by the referee's rule (+1 / -1 for +x / -x, 0 none).
int goalScored(const world::World& w);

// --- the trials (one file each) ---------------------------------------------------------------

// Commands (vx, vy, omega) as a function of time since the walk began.
using Schedule = std::function<Eigen::Vector3d(double)>;
struct WalkResult {
  double distance = 0.0, speed = 0.0, lateral = 0.0, turned = 0.0;
  bool fell = false;
  double fell_at = -1.0;
};
// Whether the walk is asked to stand (WalkEngine::stop) at a time since it began.
using StandSchedule = std::function<bool(double)>;
// The walk engine alone for `seconds`; with `falls`, the robot is put back up
// after each fall (counted) and walks on; with `stands`, it stops when they say.
WalkResult walkTrial(const TrialContext& c, const Schedule& schedule, double seconds,
                     int* falls = nullptr, const StandSchedule& stands = {});

// The table's random walk: a new seeded command every `hold` seconds in the bench file's ranges
// for `seconds`, a share `stand_share` of them "stand"; the falls (the robot is put back up
// after each). random_commands: every 2 s, none standing; stop_and_go: every 0.5 s, 3 in 10
// standing, as a behaviour's positioning near its target (short commands, stops and starts).
int randomCommandsTrial(const TrialContext& c, uint64_t seed, double seconds, double hold = 2.0,
                        double stand_share = 0.0);

struct KickResult {
  double distance = 0.0, direction = 0.0;  // m, rad (field frame, 0 = the robot's heading)
  bool fell = false;
};
// steps_first: steps on the spot before the kick, which starts once the walk has stopped and
// the robot has stood for the kick's ready_time (as the motion controller kicks in play),
// instead of from a settled stance. The ball is placed along the field's x axis, the robot's
// heading at the start: steps on the spot may turn it a little.
KickResult kickTrial(const TrialContext& c, agents::Leg foot, double ball_offset, uint64_t seed,
                     double gap = 0.015, int steps_first = 0);

struct GetUpResult {
  bool success = false;
  double seconds = 0.0;
  int attempts = 0;
};
GetUpResult getUpTrial(const TrialContext& c, bool front, uint64_t seed,
                       const std::string& snapshots = "");

struct SitResult {
  bool success = false;
  double seated_height = 0.0;  // m, the torso after 5 s of sitting
  double up_seconds = -1.0;    // from the stand request to the stance
  int falls = 0;
};
SitResult sitTrial(const TrialContext& c, uint64_t seed);

struct StrikerResult {
  bool scored = false;
  double seconds = 0.0;
  int falls = 0;
};
StrikerResult strikerTrial(const TrialContext& c, uint64_t seed, double limit);

enum class PenaltyOutcome { Goal, Saved, Missed, Timeout };
const char* penaltyOutcomeName(PenaltyOutcome o);
PenaltyOutcome penaltyTrial(const TrialContext& c, uint64_t seed, double limit);

struct BlockResult {
  bool saved = false, in_reach = false;
  int blocks = 0, falls = 0;
};
// For tuning: where the ball passes the keeper's line (m from its middle, +: its left) and how
// fast it starts (m/s); unset, seeded like the table's.
struct BlockShot {
  std::optional<double> offset, speed;
};
BlockResult blockTrial(const TrialContext& c, uint64_t seed, bool shootout,
                       const BlockShot& shot = {});

}  // namespace simsoccer::apps::motion

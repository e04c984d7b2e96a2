// The motion layer of an agent: takes what the behaviour wants (stand, walk
// at a velocity, kick with a foot, where the head looks) and the robot's
// sensors, and produces the joint targets and stiffnesses for one control
// period. It owns the walk, the kick, the goalkeeper's block and dive and the
// get-up and sit motions, switches between them only where that is safe (a kick or
// sitting down from a standing stance, the walk stopped first; the block and the dive, which
// cannot wait, at once from standing or walking), and runs the fall detector: while the robot falls
// its joints go soft (safe stiffness), once it lies still it gets up from the front or the back
// (keyframe motions), and then eases back into the stance.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "simsoccer/agents/motion/keyframe_motion.hpp"
#include "simsoccer/agents/motion/kick_engine.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::agents {

struct MotionRequest {
  // Block: the goalkeeper's block (a keyframe motion down into a wide squat
  // and back up). Dive: the goalkeeper throws itself to the side of `side`
  // (a keyframe motion; it ends lying, then the fall detector's get-up
  // applies). Both start at once from standing or walking. Sit: down into a
  // crouch on its feet (the walk stopped first) and rest there with soft
  // joints, as a Nao does when the game is over; any other request stands it
  // up again first.
  enum class Kind { Stand, Walk, Kick, Block, Dive, Sit };
  Kind kind = Kind::Stand;
  double forward = 0.0, left = 0.0, turn = 0.0;  // m/s, m/s, rad/s (robot frame)
  Leg kick_foot = Leg::Right;
  Leg side = Leg::Left;                     // a dive's side
  double head_yaw = 0.0, head_pitch = 0.0;  // rad
};

// What the motion layer reads each period (filled from a SensorFrame).
struct MotionSensors {
  std::span<const float> position;  // rad, actuator order
  Vec3 gyro = Vec3::Zero();         // rad/s, torso frame
  Vec3 accel = Vec3(0, 0, 9.81);    // m/s^2, torso frame (specific force)
  // rad, the IMU's torso angles (its attitude estimate, as the Nao's AngleX/Y/Z)
  double roll = 0.0, pitch = 0.0;
  double yaw = 0.0;
};

// The body's joint angles (body joint order, mimics applied) from the encoders (actuator order).
// A frame from before the first control period carries none (all zero): read as the stand pose
// the robot was placed in.
void measuredJointAngles(const robots::RobotModel& model, std::span<const float> position,
                         std::vector<double>& q);

struct FallDetectorParameters {
  double falling_tilt = 0.65;    // rad from upright: the robot is falling
  double lying_tilt = 1.0;       // rad: it lies ...
  double lying_rate = 0.6;       // rad/s: ... once it turns slower than this ...
  double lying_time = 0.3;       // s ... for this long
  double upright_tilt = 0.35;    // rad: a get-up that ends within this succeeded
  double safe_stiffness = 0.15;  // while falling and lying
  double head_stiffness = 0.6;   // the head's stiffness in normal motion
  // Try to get up once lying still (from the back: roll onto the front
  // first). Off: the robot stays down, soft (the referee takes it out as an
  // inactive player).
  bool get_up = true;
};

enum class MotionState {
  Easing,
  Stance,
  Walking,
  Kicking,
  Blocking,
  Diving,
  SittingDown,
  Sitting,
  StandingUp,
  Falling,
  Lying,
  GettingUp
};
const char* motionStateName(MotionState s);

struct MotionCounters {
  int falls = 0, get_ups = 0, failed_get_ups = 0, kicks = 0, blocks = 0, dives = 0, sits = 0;
};

// The controller's keyframe motions, one file each in configs/motions/
// (<member name>.yaml).
struct KeyframeMotions {
  KeyframeMotion get_up_front, get_up_back, block, dive_left, dive_right;
  KeyframeMotion sit_down;  // from the stance into the crouch; its last frame's stiffness rests
  KeyframeMotion stand_up;  // from the crouch back to the stand pose
};

class MotionController {
 public:
  MotionController(const robots::RobotModel& model, KeyframeMotions motions,
                   const WalkParameters& walk = {}, const KickParameters& kick = {},
                   const FallDetectorParameters& fall = {});

  // One control period: writes 25 targets (rad) and stiffnesses (0..1) in
  // actuator order.
  void update(double dt, const MotionSensors& sensors, const MotionRequest& request,
              std::span<float> position, std::span<float> stiffness);
  // Starts over from the measured joints (after the robot was moved by the
  // referee, e.g. a penalty): eases into the stance (sitting: stands up first).
  void restart();

  MotionState state() const { return state_; }
  const MotionCounters& counters() const { return counters_; }
  // Torso tilt from upright (rad), from the accelerometer (filtered).
  double tilt() const { return tilt_; }
  // The keyframe motion playing (get-up, roll, block, dive, sit down, stand up), or none.
  const KeyframeMotion* keyframeMotion() const {
    return player_.active() ? player_.motion() : nullptr;
  }
  bool upright() const;
  // Put on its feet by someone (the referee taking out a player or setting
  // up the shoot-out's next kick) while it falls or lies (at rest: `rate`,
  // rad/s), gets up, or dives (after its first 0.3 s): upright by the IMU's
  // angles (the filtered accelerometer lags, and reads the legs folding under
  // a motion's targets) with the legs in the stand pose; during a get-up or
  // a dive also the motion's targets far from it (a get-up ends in it).
  bool placedOnItsFeet(const MotionSensors& sensors, const std::vector<double>& measured,
                       double rate) const;
  const WalkEngine& walk() const { return walk_; }
  const robots::RobotModel& model() const { return model_; }
  // The feet's midpoint in the perception's robot frame (m): LegKinematics::feetCentre from
  // this period's encoders and IMU angles.
  Eigen::Vector2d feetCentre(const MotionSensors& sensors) const;

 private:
  void enter(MotionState s);
  // Enters `s` playing `motion` from the measured joints (its first period
  // included): the get-up, the block and the dive.
  void startKeyframes(MotionState s, const KeyframeMotion& motion,
                      const std::vector<double>& measured, double dt);
  // From sitting (or half-way down): starts the stand-up motion from `measured`.
  void standUp(const std::vector<double>& measured);
  // After a keyframe motion that ends on the feet: ease into a fresh walk's stance.
  void easeIntoStance();
  // Drops whatever motion runs and eases into the stance from `measured`
  // (sitting: stands up first); the fall detector starts again from the IMU's angles.
  void restartFrom(const std::vector<double>& measured, const MotionSensors& sensors);

  const robots::RobotModel& model_;
  KeyframeMotions motions_;
  WalkParameters walk_parameters_;
  KickParameters kick_parameters_;
  FallDetectorParameters fall_;
  WalkEngine walk_;
  KickEngine kick_;
  KeyframePlayer player_;
  MotionState state_ = MotionState::Easing;
  MotionCounters counters_;
  std::vector<double> targets_, ease_from_;
  std::vector<int> leg_joints_;  // body joint indices of both legs
  double state_time_ = 0.0, still_for_ = 0.0, tilt_ = 0.0;
  double standing_for_ = 0.0;        // s in the stance with the walk stopped (a kick's ready_time)
  Vec3 gravity_ = Vec3(0, 0, 9.81);  // low-passed accelerometer
  double stiffness_ = 1.0;
  int head_yaw_ = -1, head_pitch_ = -1;  // body joint indices
  bool restart_ = true;
};

// A MotionSensors view of a SensorFrame-like struct (the DDS message or the
// world's frame: both name their fields the same).
template <class Frame>
MotionSensors motionSensors(const Frame& f) {
  MotionSensors s;
  s.position = std::span<const float>(&f.position[0], protocol::kActuators);
  s.gyro = Vec3(f.gyroscope[0], f.gyroscope[1], f.gyroscope[2]);
  s.accel = Vec3(f.accelerometer[0], f.accelerometer[1], f.accelerometer[2]);
  s.roll = f.angles[0];
  s.pitch = f.angles[1];
  s.yaw = f.angles[2];
  return s;
}

}  // namespace simsoccer::agents

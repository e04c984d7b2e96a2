// An omnidirectional walk for the Nao: an open-loop step generator in the
// lineage of rUNSWift's Walk2014 and B-Human's walk (nao.md section 8):
// fixed-duration steps (default 250 ms), the swing foot lifted on a sine and
// moved to its next placement with a smoothstep, the torso carried along the
// body path at the commanded speed with a lateral sway over the support foot,
// and balance feedback from the gyroscope on the support ankle. Everything
// reaches the joints through LegKinematics: the agent sends joint targets
// only (no forces, no teleporting).
//
// Frames: the walk's 2D "odometry" frame is where the robot started walking
// (x forward, y left); a pose there is (x, y, yaw).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "simsoccer/agents/motion/leg_kinematics.hpp"

namespace simsoccer::agents {

struct WalkParameters {
  double step_period = 0.25;    // s, one step (half a gait cycle)
  double foot_lift = 0.016;     // m, swing apex
  double ankle_height = 0.255;  // m, ankle below the torso origin while walking
  double step_width = 0.10;     // m, between the feet's centres
  double sway = 0.018;          // m, torso over the support foot at mid-step
  double torso_lean = 0.0;      // rad, forward
  double torso_offset = -0.01;  // m, torso ahead of the feet's middle
  // Measured calibration: with these settings the robot covers 9 % more
  // ground than its commanded step lengths (the support leg's servos give
  // under the load, the landing foot reaches further), so forward steps are
  // shortened by this factor; odometry reports the intended distance.
  double forward_scale = 0.92;
  double max_forward = 0.075;    // m per step before scaling (0.3 m/s at 4 steps/s)
  double max_backward = 0.04;    // m per step
  double max_side = 0.05;        // m per sideways step (taken every other step)
  double max_turn = 0.4;         // rad per turning step (taken every other step)
  double max_accel = 0.02;       // m per step per step, forward
  double max_side_accel = 0.01;  // m per step per step (average sideways step)
  double max_turn_accel = 0.05;  // rad per step per step (average turn per step)
  // Turning on the spot (no step forward or sideways wanted or under way): a turning step may be
  // larger (the command's and the heading hold's turn together; the command alone stays inside
  // max_turn) and the average turn ramps up faster. The same while walking tips the robot over.
  // 0: as walking.
  double max_turn_on_spot = 0.0;        // rad per turning step
  double max_turn_accel_on_spot = 0.0;  // rad per step per step
  // The support leg's hip roll sags under the body's weight (the servo is a
  // stiff spring, not a rigid joint): commanded this much further, peaking
  // at mid-step, so the swing foot stays off the ground.
  double hip_roll_compensation = 0.05;  // rad
  // Heading hold: each step turns by this share of the difference between
  // the walk's own heading and the IMU's torso yaw (feet slip and the
  // mechanism is not perfectly symmetric; open loop the robot drifts).
  double heading_gain = 0.5;
  // Settling to a stop (stop(true), to sit down), heading errors below this
  // are left alone (rad): the torso's yaw sways about 0.01 rad with the
  // steps, and corrected on each step it can keep a robot stepping on the
  // spot. (A plain stop keeps correcting: in 5 v 5 matches, robots asked to
  // stand that settled fell twice as often as robots stepping on the spot.)
  double stop_heading_tolerance = 0.03;
  // Starting again within this long (s) after the walk stopped: the first step only shifts the
  // weight (the torso sways over the right foot and back, no foot lifts or moves), then the
  // right foot steps, as in a walk under way. The body still rocks from the last steps, and a
  // foot lifted at once can be the one it leans on; from a calm stance a step at once is safe,
  // and quicker. 0: never (the Nao's walk does not fall without it).
  double start_shift_time = 0.0;
  double ankle_pitch_gyro = 0.05;  // rad per rad/s of torso pitch rate
  double ankle_roll_gyro = 0.05;   // rad per rad/s of torso roll rate
  // The gyro's low-pass for that feedback: the share of each new reading
  // (1: none). Smoothing delays the feedback, as the actuation delay does.
  double gyro_smoothing = 0.5;
  // A step ends when its time is up, open loop, unless the torso still leans towards the support
  // foot further than support_lean (rad, the IMU's roll; the walk's own sway stays inside it):
  // then the swing foot is down but has not taken the weight, and lifting the support foot would
  // tip the robot over it. The step waits in double support until the lean is back, for at most
  // max_support_hold (s). 0: never (open loop).
  double support_lean = 0.1;
  double max_support_hold = 0.0;
  double stiffness = 1.0;
};

// What the walk reads from the IMU each period.
struct WalkSensors {
  Vec3 gyro = Vec3::Zero();  // rad/s, torso frame
  double roll = 0.0;         // rad, the torso's attitude (positive: leaning right)
  double yaw = 0.0;          // rad
};

struct Pose2 {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

class WalkEngine {
 public:
  WalkEngine(const robots::RobotModel& model, const WalkParameters& parameters = {});

  // The wanted velocity in the robot frame (m/s, m/s, rad/s); clamped to the
  // parameters' limits, reached over a few steps. Zero: the robot steps on
  // the spot until stop().
  void setVelocity(double forward, double left, double turn);
  // Finishes the step under way, then stands with the feet together once
  // the heading hold has nothing left to correct. `settle` (coming to rest
  // to kick or to sit down): heading errors under stop_heading_tolerance are
  // left alone, so the yaw's sway cannot keep it stepping.
  void stop(bool settle = false);
  bool walking() const { return walking_; }

  // Advances by `dt` and writes the joint targets (one per body joint, rad;
  // only the legs are written: the arms and the head are left as they are
  // in `targets`).
  void update(double dt, const WalkSensors& imu, std::vector<double>& targets);

  // Where the walk thinks the body is (odometry frame), and the foot placements.
  Pose2 odometry() const { return odometry_; }
  double phase() const { return phase_; }
  Leg supportLeg() const { return support_; }
  const LegKinematics& kinematics() const { return kinematics_; }
  const WalkParameters& parameters() const { return p_; }
  // Before the first step: the legs' targets eased from `from` (body joint
  // angles, e.g. the model's stand pose) into the walk's stance, fully there
  // after `kEaseTime` (`t`: seconds since easing began).
  static constexpr double kEaseTime = 0.5;
  void easeIn(const std::vector<double>& from, double t, std::vector<double>& targets);
  // Standing (not walking): takes the feet where they stand, from the measured body joint angles,
  // as its placements (the body over their middle, heading halfway between them), so that
  // easing in and standing keep them there and the first steps put them in the gait's stance.
  // A robot moved by the referee mid-step stands with one foot ahead: eased into the gait's
  // stance its feet would slide on the carpet. Left as it is with a foot off the ground.
  void standWhereTheFeetAre(const std::vector<double>& joints);

 private:
  void startStep();
  LegSolution solve(const Pose2& body, double sway_y, const Pose2& left, const Pose2& right,
                    double left_lift, double right_lift);

  LegKinematics kinematics_;
  WalkParameters p_;
  bool walking_ = false, stopping_ = false, settling_ = false;
  bool shifting_ = false;   // this step only shifts the weight (start_shift_time)
  double stood_for_ = 1e9;  // s since the walk stopped (never walked: as if long ago)
  double phase_ = 0.0;  // 0..1 within the step
  double held_ = 0.0;   // s the step's end has waited for the lean (max_support_hold)
  Leg support_ = Leg::Right;
  Pose2 body_, body_start_, body_end_;
  Pose2 odometry_;                 // the intended path (unscaled steps)
  Pose2 foot_[2];                  // current placements (left, right)
  Pose2 swing_start_, swing_end_;  // the swing foot's path this step
  // Per-step averages (x m, y m, yaw rad): wanted, and reached so far; the step itself.
  Eigen::Vector3d wanted_ = Eigen::Vector3d::Zero(), average_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d step_ = Eigen::Vector3d::Zero();
  Vec3 gyro_filtered_ = Vec3::Zero();
  double yaw_ = 0.0, yaw_offset_ = 0.0;  // IMU yaw, and its value when the walk's odometry began
  bool yaw_known_ = false;
  double intended_yaw_ = 0.0;  // the heading the commands asked for (odometry frame)
  LegSolution last_{};
  bool have_last_ = false;
};

}  // namespace simsoccer::agents

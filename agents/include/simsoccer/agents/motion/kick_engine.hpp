// A forward kick with either foot from the walk's stance, straight ahead
// (aiming is the behaviour's part: it lines the robot up behind the ball;
// swinging the foot diagonally was tried and the ball still left along the
// foot's face): shift the torso over the support foot, lift and draw back the
// kicking foot, swing it through, draw it back, put it down, shift back. Keyframes of the torso's
// sideways offset and the kicking foot's offset (along the aim, and up), smoothly interpolated,
// reach the joints through LegKinematics: joint targets only.
#pragma once

#include <vector>

#include "simsoccer/agents/motion/walk_engine.hpp"

namespace simsoccer::agents {

struct KickParameters {
  double shift = 0.052;  // m, torso towards the support foot
  // The foot drawn back high (knee bent) and swung down and through: the knee
  // straightening adds to the hip's swing. Drawn back low (lift 0.035 m) the
  // foot reached 1.5 m/s at the ball only after 0.08 m, and a longer draw-back
  // dragged the toe on the carpet.
  double lift = 0.105;        // m, kicking foot up, drawn back
  double draw_back = 0.08;    // m, behind its stance position
  double reach = 0.10;        // m, ahead of it at the end of the swing
  double shift_time = 0.6;    // s
  double lift_time = 0.3;     // s
  double swing_time = 0.05;   // s (the foot through the ball: faster than the servos follow)
  double retract_time = 0.3;  // s
  double lower_time = 0.3;    // s
  double return_time = 0.6;   // s
  // s held in the stance after the kick before the robot may walk again (a K1 that walked off
  // at once after its kick fell now and then; the Nao needs none).
  double settle_time = 0.0;
  // After settle_time the kick holds the stance until the torso turns slower than calm_rate
  // (rad/s, gyroscope) for calm_time (s), at most calm_wait (s) longer: a K1 that walked off
  // while it still rocked from its kick (0.16 rad of roll each way, 1.3 s a swing) rocked further
  // with the walk's sway and fell. 0: no wait (the Nao needs none).
  double calm_rate = 0.0;
  double calm_time = 0.3;
  double calm_wait = 2.0;
  // s standing in the stance, the walk stopped, before a requested kick starts (the robot still
  // sways from its last steps; the Nao needs none).
  double ready_time = 0.0;
  double hip_roll_compensation = 0.07;  // rad, the support hip's sag (see WalkParameters)
  double swing_height = 0.02;  // m, the kicking foot up at the swing's end (the servos lag the
                               // path: measured, the sole meets the ball about 0.03 m up, the
                               // foot's face at the ball's middle)
  // m, the kicking foot moved away from the support foot (negative: towards it) while it is
  // lifted and swung, back in place as it is retracted. Measured on a K1 (pipelined periods):
  // without it a ball 2 cm inside the foot's middle went 3.2-3.5 m and one 2 cm outside
  // 4.4-4.5 m; with the foot 2 cm towards the support foot every ball within 2 cm of the
  // middle went 4.6-5.4 m. The Nao at a 10 ms step: with 0 a ball 1-2 cm inside the left
  // foot's middle went 2.9-3.0 m (the others 4.0-4.6 m; the table's kicks 85 % >= 3 m); with
  // -0.01 every ball within 2 cm went 3.2-5.4 m (100 %).
  double swing_out = -0.01;
  // With both feet down after the swing, a torso tilted (roll or pitch, from the IMU's angles)
  // more than tilt_deadband (rad) beyond how it stood when the kick started is met by the legs:
  // they move the torso tilt_gain (m/rad) times the excess towards the raised side, over the
  // feet, so that the mass comes back inside the foot the robot has tipped onto. (Setting the
  // legs as for the tilted torso, so that the raised foot reaches down and pushes, tips it
  // further: the ground can only push that foot up.) The kick holds the stance until the tilt
  // is back within the deadband (at most calm_wait). 0: off.
  double tilt_gain = 0.0;
  double tilt_deadband = 0.08;
};

// The IMU's torso angles (rad, as MotionSensors), for the kick's tilt reflex.
struct TorsoTilt {
  double roll = 0.0, pitch = 0.0;
};

class KickEngine {
 public:
  KickEngine(const robots::RobotModel& model, const WalkParameters& stance = {},
             const KickParameters& parameters = {});

  // Starts a kick with `foot` from the stance the robot stands in: `joints`, the measured
  // joint angles (body joint order, mimics applied), place the kicking foot against the
  // support foot. After walking the feet stand a few cm off the gait's stance (a K1 after three
  // steps on the spot: 0.17 m apart, not 0.19), and kicking from the gait's stance pushed the
  // legs against the ground. The support foot stays where it stands; the kicking foot is put
  // in the gait's stance while it is lifted. Without joints (or with a foot off the ground):
  // the gait's stance.
  void start(Leg foot, const std::vector<double>& joints = {});
  bool active() const { return active_; }
  double duration() const;
  const LegKinematics& kinematics() const { return kinematics_; }
  // Advances by dt and writes the legs' targets (body joint order). `tilt`: the torso's angles
  // now (the first update's are the reference the reflex measures from).
  void update(double dt, const Vec3& gyro, std::vector<double>& targets,
              const TorsoTilt& tilt = {});

 private:
  LegKinematics kinematics_;
  WalkParameters stance_;
  KickParameters p_;
  bool active_ = false;
  Leg foot_ = Leg::Right;
  double t_ = 0.0;
  double calm_for_ = 0.0;  // s the torso has turned slower than calm_rate
  TorsoTilt tilt_start_;   // the torso's angles at the kick's first update
  bool have_tilt_start_ = false;
  // The kicking foot against the support foot at the start (x, y, yaw in the support foot's
  // frame; the gait's stance: 0, +-step_width, 0).
  Eigen::Vector3d start_offset_ = Eigen::Vector3d::Zero();
  LegSolution last_{};
  bool have_last_ = false;
};

}  // namespace simsoccer::agents

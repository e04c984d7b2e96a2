// Walking up to a ball and kicking it towards a direction, in the robot frame
// alone (what the robot's cameras see and its IMU's heading; no
// self-localisation): the striker's last step, and the whole of the Booster
// locomotion service's visual kick, which simsoccer plays for a robot driven
// through that API (booster/, docs/booster.md).
#pragma once

#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"

namespace simsoccer::agents {

// The last step to a kick: the ball seen at (ball_x, ball_y) (m, robot frame,
// from the feet's midpoint: SoccerBehaviour::Input::feet) to be kicked towards `aim` (rad, robot
// frame). `foot` turns to the ball's side once the ball is half the foot's offset past the middle;
// answers a Kick with it once the ball lies in front of it within the
// config's tolerances, else a small walk step towards that (forward at most
// `max_forward` m/s).
MotionRequest lineUpForKick(const BehaviourConfig& config, double ball_x, double ball_y, double aim,
                            double max_forward, Leg& foot);

// The head turned to a ball at (x, y) (robot frame, m), pitched by its
// distance (near: down at the feet).
void lookAt(double x, double y, MotionRequest& request);

// Where the robot last saw the ball (its perception), robot frame.
struct BallSighting {
  double x = 0.0, y = 0.0;  // m, where it was seen (relative to the robot then)
  double age = -1.0;        // s since seen (< 0: never)
};

// Walks to the ball it sees, gets behind it on the line of the aim, lines up
// a foot and kicks; then goes after the ball again, for as long as it runs.
// The aim is a direction in the IMU's heading (yaw) frame, so it holds while
// the robot walks and turns. Without a ball in sight it stands and sweeps the
// head, and after a sweep turns on the spot towards where the ball was seen
// last.
class KickApproach {
 public:
  explicit KickApproach(const BehaviourConfig& config) : config_(config) {}

  // Starts, aimed straight ahead of the robot's heading `yaw` (IMU, rad).
  void start(double time, double yaw);
  // Aims at `direction` (rad, robot frame when the robot's heading was `yaw`).
  void aimAt(double direction, double yaw);
  // One period: the ball as last seen, the heading now, the motion layer's
  // state and the feet's midpoint (robot frame, m: MotionController::feetCentre,
  // which the ball is lined up against); the request, head included.
  MotionRequest update(double time, const BallSighting& ball, double yaw, MotionState motion,
                       const Eigen::Vector2d& feet);

 private:
  BehaviourConfig config_;
  double aim_yaw_ = 0.0;
  double started_ = 0.0;
  double commit_until_ = -1.0;  // a kick decided is asked for until the motion layer kicks
  Leg foot_ = Leg::Right;
  double last_side_ = 1.0;  // which way the ball was seen last (+1 left)
};

}  // namespace simsoccer::agents

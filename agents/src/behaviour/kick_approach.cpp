#include "simsoccer/agents/behaviour/kick_approach.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace simsoccer::agents {
namespace {

constexpr double kPi = std::numbers::pi;

double wrap(double a) {
  return std::remainder(a, 2 * kPi);
}

}  // namespace

MotionRequest lineUpForKick(const BehaviourConfig& c, double ball_x, double ball_y, double aim,
                            double max_forward, Leg& foot) {
  // The foot changes only once the ball is half a foot's offset past the
  // middle: switching as it crossed the middle, a K1 (its sway moved a ball
  // seen near the torso's middle 2-3 cm each way a step) stepped left and
  // right under the ball for 20 s without kicking.
  const double keep = 0.5 * c.kick_ball_y;
  if (foot == Leg::Left && ball_y < -keep) foot = Leg::Right;
  if (foot == Leg::Right && ball_y > keep) foot = Leg::Left;
  const double foot_y = foot == Leg::Left ? c.kick_ball_y : -c.kick_ball_y;
  const double ex = ball_x - c.kick_ball_x, ey = ball_y - foot_y;
  MotionRequest r;
  if (std::abs(ex) < c.kick_tolerance_x && std::abs(ey) < c.kick_tolerance_y &&
      std::abs(aim) < c.kick_tolerance_angle) {
    r.kind = MotionRequest::Kind::Kick;
    r.kick_foot = foot;
    return r;
  }
  r.kind = MotionRequest::Kind::Walk;
  r.forward = std::clamp(0.9 * ex, -0.06, max_forward);
  r.left = std::clamp(0.9 * ey, -0.06, 0.06);
  r.turn = std::clamp(1.0 * aim, -0.4, 0.4);
  return r;
}

void lookAt(double x, double y, MotionRequest& r) {
  const double d = std::hypot(x, y);
  r.head_yaw = std::atan2(y, x);
  r.head_pitch = std::clamp(std::atan2(0.45, std::max(d, 0.1)) - 0.35, -0.4, 0.45);
}

void KickApproach::start(double time, double yaw) {
  aim_yaw_ = yaw;
  started_ = time;
  commit_until_ = -1.0;
}

void KickApproach::aimAt(double direction, double yaw) {
  aim_yaw_ = wrap(yaw + direction);
}

MotionRequest KickApproach::update(double time, const BallSighting& ball, double yaw,
                                   MotionState motion, const Eigen::Vector2d& feet) {
  const bool down = motion == MotionState::Falling || motion == MotionState::Lying ||
                    motion == MotionState::GettingUp || motion == MotionState::Diving;
  if (motion == MotionState::Kicking || down) commit_until_ = -1.0;
  const double aim = wrap(aim_yaw_ - yaw);  // robot frame
  const bool seen = ball.age >= 0.0 && ball.age < 1.0;
  MotionRequest r;
  if (!seen) {
    // Search: stand and sweep the head (4 s a sweep); after a sweep, turn on
    // the spot towards where the ball went out of sight.
    r.head_yaw = 2.0 * std::sin(2 * kPi * (time - started_) / 4.0);
    r.head_pitch = 0.2;
    const double unseen = ball.age < 0.0 ? time - started_ : ball.age;
    if (unseen > 4.0) {
      r.kind = MotionRequest::Kind::Walk;
      r.turn = 0.5 * last_side_;
    }
    return r;
  }
  last_side_ = ball.y >= 0.0 ? 1.0 : -1.0;
  if (time < commit_until_) {
    r.kind = MotionRequest::Kind::Kick;
    r.kick_foot = foot_;
    lookAt(ball.x, ball.y, r);
    return r;
  }
  const double dx = std::cos(aim), dy = std::sin(aim);
  const double to_ball = std::hypot(ball.x, ball.y);
  // Behind the ball: the robot's projection on the aim line is behind it.
  const double along = -(ball.x * dx + ball.y * dy);
  const double across = ball.x * dy - ball.y * dx;
  const bool behind = along < -0.1 && std::abs(across) < std::max(0.25, -0.8 * along);
  if (to_ball > config_.approach_distance + 0.2 || !behind) {
    // To the approach point behind the ball, facing the aim (beside or in
    // front of the ball: round it on the near side).
    double tx = ball.x - dx * config_.approach_distance;
    double ty = ball.y - dy * config_.approach_distance;
    if (!behind && along > -0.2) {
      const double side = across >= 0 ? 1.0 : -1.0;
      tx = ball.x - dx * 0.3 - dy * side * 0.4;
      ty = ball.y - dy * 0.3 + dx * side * 0.4;
    }
    r.kind = MotionRequest::Kind::Walk;
    const double dist = std::hypot(tx, ty);
    if (dist > 0.5) {
      // Far: turn towards it and walk, forward speed falling off with the angle.
      const double bearing = std::atan2(ty, tx);
      r.turn = std::clamp(1.2 * bearing, -config_.max_turn, config_.max_turn);
      r.forward = config_.max_forward * std::max(0.0, std::cos(bearing)) *
                  (std::abs(bearing) > 0.8 ? 0.0 : 1.0);
      r.left = std::clamp(0.5 * ty, -config_.max_side, config_.max_side) * 0.5;
    } else {
      r.forward = std::clamp(0.8 * tx, -0.1, config_.max_forward);
      r.left = std::clamp(0.8 * ty, -config_.max_side, config_.max_side);
      r.turn = std::clamp(1.2 * aim, -config_.max_turn, config_.max_turn);
    }
  } else {
    r = lineUpForKick(config_, ball.x - feet.x(), ball.y - feet.y(), aim, 0.15, foot_);
    if (r.kind == MotionRequest::Kind::Kick) commit_until_ = time + 1.5;
  }
  lookAt(ball.x, ball.y, r);
  return r;
}

}  // namespace simsoccer::agents

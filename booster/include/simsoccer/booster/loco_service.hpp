// The Booster SDK's locomotion service (rt/LocoApiTopicReq and ...Resp) as
// far as simsoccer answers it for one robot: its mode machine, head turns,
// kicks, and an answer to every request, in the SDK's RPC conventions (JSON
// header {"api_id", "expect_response"} and body; answers {"status"} and a body).
//
// Modes (RobotMode): Damping (joints limp but damped), Prepare (standing,
// holding the stand pose: the robot's own position servos), Custom (the
// client's LowCmd joint commands, rt/joint_ctrl), Walking and Soccer
// (Booster's walking controller, which runs only on Booster's tools: here
// simsoccer's own walk for the robot, the built-in agents' motion layer,
// where the robot has one). Move sets the walk's velocity in Walking and
// Soccer; RotateHead turns the head in Prepare, Walking and Soccer; GetUp
// answers 0 there (the walk's fall detector gets the robot up once it lies
// still). Where the robot also has a kick approach, Shoot kicks once where
// the robot stands and VisualKick {"start", "version"} starts and stops the
// visual kick (the robot goes to the ball it sees and kicks it the way
// rt/kick_ball says, again and again until stopped; it needs the
// simulation's perception), both in Walking and Soccer with the robot on its feet. As the SDK's
// status codes say: a call the robot has no motion for (LieDown, SwitchGait, ...) answers 501
// (server refused), one its state does not allow (Move in Prepare, RotateHead in Custom, a kick
// while it lies) 502 (state transition failed); malformed requests and unknown api ids 400.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace simsoccer::booster {

// The SDK's RobotMode values (robot_shared.hpp).
enum class RobotMode : int { Damping = 0, Prepare = 1, Walking = 2, Custom = 3, Soccer = 4 };
const char* modeName(RobotMode m);

// The SDK's RPC status codes (rpc/error.hpp).
inline constexpr int64_t kStatusSuccess = 0;
inline constexpr int64_t kStatusBadRequest = 400;
inline constexpr int64_t kStatusServerRefused = 501;
inline constexpr int64_t kStatusStateTransitionFailed = 502;

// LocoApiId values answered (b1_loco_api.hpp).
enum class LocoApi : int {
  ChangeMode = 2000,
  Move = 2001,
  RotateHead = 2004,
  LieDown = 2007,
  GetUp = 2008,
  GetMode = 2017,
  GetStatus = 2018,
  Shoot = 2024,
  GetUpWithMode = 2025,
  ResetOdometry = 2031,
  VisualKick = 2038,
  SwitchGait = 2042,
  RotateHeadWithTime = 2043,
};
// The name of every other LocoApiId of the SDK (b1_loco_api.hpp: hands, dances, sounds,
// trajectories, queries), answered 501 (not available in simsoccer); nullptr for an id the SDK
// does not have (answered 400).
const char* unservedLocoApiName(int api_id);

struct RpcAnswer {
  bool respond = true;  // false: the request said expect_response false
  int64_t status = kStatusSuccess;
  std::string body;  // JSON ("" for none)
};

struct HeadTarget {
  double pitch = 0.0, yaw = 0.0;  // rad
};

// Move's velocity in the robot frame: m/s forward, m/s left, rad/s.
struct WalkVelocity {
  double vx = 0.0, vy = 0.0, vyaw = 0.0;
};

// What simsoccer can do for a robot through the service.
struct LocoCapabilities {
  bool walk = false;    // simsoccer's walk: Walking and Soccer are served
  bool kicks = false;   // and a kick approach: Shoot and VisualKick (with walk)
  bool vision = false;  // the simulation's perception, which the visual kick needs
};

class LocoService {
 public:
  explicit LocoService(RobotMode initial = RobotMode::Prepare, LocoCapabilities can = {})
      : mode_(initial), walk_(can.walk), kicks_(can.walk && can.kicks), vision_(can.vision) {}

  // One request: its header and body as the client sent them (any bytes).
  RpcAnswer handle(std::string_view header, std::string_view body);

  RobotMode mode() const { return mode_; }
  // The head turn RotateHead asked for (held in Prepare, Walking, Soccer), if any.
  const std::optional<HeadTarget>& headTarget() const { return head_; }
  // Walking or Soccer: simsoccer's walk drives the robot.
  bool walking() const { return mode_ == RobotMode::Walking || mode_ == RobotMode::Soccer; }
  // The velocity of the last Move (zero on entering Walking or Soccer).
  const WalkVelocity& velocity() const { return velocity_; }
  // The visual kick runs (VisualKick started it; stopping it, leaving
  // Walking and Soccer, or the robot falling ends it) and its version (0:
  // V1, 1: V2, "stronger" on the robot; simsoccer's K1 has one kick).
  bool visualKick() const { return visual_kick_; }
  // VisualKick starts so far (a stop and a start between two looks is a new start).
  uint64_t visualKickStarts() const { return visual_kick_starts_; }
  int visualKickVersion() const { return visual_kick_version_; }
  // True once for each Shoot taken.
  bool takeShoot() { return std::exchange(shoot_, false); }
  // ResetOdometry requests so far (the odometry's origin moves to the robot at each).
  uint64_t odometryResets() const { return odometry_resets_; }
  // Whether the robot is down (falling, lying, getting up): kicks answer 502
  // and a running visual kick ends.
  void setDown(bool down);

  uint64_t requests() const { return requests_; }
  uint64_t refused() const { return refused_; }      // 501 and 502
  uint64_t malformed() const { return malformed_; }  // 400

 private:
  RobotMode mode_;
  bool walk_ = false, kicks_ = false, vision_ = false;
  bool down_ = false, visual_kick_ = false, shoot_ = false;
  int visual_kick_version_ = 0;
  uint64_t visual_kick_starts_ = 0, odometry_resets_ = 0;
  std::optional<HeadTarget> head_;
  WalkVelocity velocity_;
  uint64_t requests_ = 0, refused_ = 0, malformed_ = 0;
};

}  // namespace simsoccer::booster

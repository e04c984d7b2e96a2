// The Booster SDK's locomotion service (rt/LocoApiTopicReq and ...Resp) as
// far as simsoccer answers it for one robot: its mode machine, head turns,
// and an answer to every request, in the SDK's RPC conventions (JSON header
// {"api_id", "expect_response"} and body; answers {"status"} and a body).
//
// Modes (RobotMode): Damping (joints limp but damped), Prepare (standing,
// holding the stand pose: the robot's own position servos), Custom (the
// client's LowCmd joint commands, rt/joint_ctrl). Walking and Soccer need
// Booster's walking controller, which runs only on Booster's tools: they,
// Move, GetUp, kicks and the other motion calls are refused with status 501
// (server refused) until simsoccer has its own K1 walk. Malformed requests
// get 400; unknown api ids 400.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace simsoccer::booster {

// The SDK's RobotMode values (robot_shared.hpp).
enum class RobotMode : int { Damping = 0, Prepare = 1, Walking = 2, Custom = 3, Soccer = 4 };
const char* modeName(RobotMode m);

// The SDK's RPC status codes (rpc/error.hpp).
inline constexpr int64_t kStatusSuccess = 0;
inline constexpr int64_t kStatusBadRequest = 400;
inline constexpr int64_t kStatusServerRefused = 501;

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
  VisualKick = 2038,
  SwitchGait = 2042,
  RotateHeadWithTime = 2043,
};

struct RpcAnswer {
  bool respond = true;  // false: the request said expect_response false
  int64_t status = kStatusSuccess;
  std::string body;  // JSON ("" for none)
};

struct HeadTarget {
  double pitch = 0.0, yaw = 0.0;  // rad
};

class LocoService {
 public:
  explicit LocoService(RobotMode initial = RobotMode::Prepare) : mode_(initial) {}

  // One request: its header and body as the client sent them (any bytes).
  RpcAnswer handle(std::string_view header, std::string_view body);

  RobotMode mode() const { return mode_; }
  // The head turn RotateHead asked for (held in Prepare), if any.
  const std::optional<HeadTarget>& headTarget() const { return head_; }

  uint64_t requests() const { return requests_; }
  uint64_t refused() const { return refused_; }      // 501: not available in simsoccer
  uint64_t malformed() const { return malformed_; }  // 400

 private:
  RobotMode mode_;
  std::optional<HeadTarget> head_;
  uint64_t requests_ = 0, refused_ = 0, malformed_ = 0;
};

}  // namespace simsoccer::booster

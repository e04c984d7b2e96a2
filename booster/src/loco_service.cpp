#include "simsoccer/booster/loco_service.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace simsoccer::booster {

using nlohmann::json;

const char* unservedLocoApiName(int api_id) {
  // The SDK's LocoApiId values (include/booster/robot/b1/b1_loco_api.hpp) that LocoService
  // does not serve.
  static constexpr std::pair<int, const char*> kUnserved[] = {
      {2005, "WaveHand"},
      {2006, "RotateHeadWithDirection"},
      {2009, "MoveHandEndEffector"},
      {2010, "ControlGripper"},
      {2011, "GetFrameTransform"},
      {2012, "SwitchHandEndEffectorControlMode"},
      {2013, "ControlDexterousHand"},
      {2015, "Handshake"},
      {2016, "Dance"},
      {2019, "PushUp"},
      {2020, "PlaySound"},
      {2021, "StopSound"},
      {2022, "GetRobotInfo"},
      {2023, "StopHandEndEffector"},
      {2026, "ZeroTorqueDrag"},
      {2027, "RecordTrajectory"},
      {2028, "ReplayTrajectory"},
      {2029, "WholeBodyDance"},
      {2030, "UpperBodyCustomControl"},
      {2032, "LoadCustomTrainedTraj"},
      {2033, "ActivateCustomTrainedTraj"},
      {2034, "UnloadCustomTrainedTraj"},
      {2035, "EnterWBCGait"},
      {2036, "ExitWBCGait"},
      {2037, "MoveDualHandEndEffector"},
      {2039, "LionDancePrepare"},
      {2040, "LionDanceStart"},
      {2041, "LionDanceMove"},
      {2044, "GetSensors"},
      {2045, "GetHands"},
      {2046, "GetRobotModel"},
      {2047, "GetTrainedTrajStatus"},
      {2050, "HandOnChestGreeting"}};
  for (const auto& [id, name] : kUnserved)
    if (id == api_id) return name;
  return nullptr;
}

const char* modeName(RobotMode m) {
  switch (m) {
    case RobotMode::Damping:
      return "damping";
    case RobotMode::Prepare:
      return "prepare";
    case RobotMode::Walking:
      return "walking";
    case RobotMode::Custom:
      return "custom";
    case RobotMode::Soccer:
      return "soccer";
  }
  return "?";
}

namespace {

// A JSON object from a request's bytes; nullopt if it is not one.
std::optional<json> parseObject(std::string_view text) {
  json j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  return j;
}

// A finite number field of an object.
std::optional<double> number(const json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  const double v = it->get<double>();
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

RpcAnswer error(int64_t status, const std::string& why) {
  RpcAnswer a;
  a.status = status;
  a.body = json{{"error", why}}.dump();
  return a;
}

}  // namespace

void LocoService::setDown(bool down) {
  down_ = down;
  if (down) visual_kick_ = shoot_ = false;
}

RpcAnswer LocoService::handle(std::string_view header_text, std::string_view body_text) {
  ++requests_;
  const std::optional<json> header = parseObject(header_text);
  const std::optional<double> api = header ? number(*header, "api_id") : std::nullopt;
  if (!api || *api != std::floor(*api) || std::abs(*api) > 1e9) {
    ++malformed_;
    return error(kStatusBadRequest, "the header is not {\"api_id\": N, ...}");
  }
  bool respond = true;
  if (const auto it = header->find("expect_response"); it != header->end() && it->is_boolean())
    respond = it->get<bool>();
  // An empty body is an empty object (GetMode sends none).
  const std::optional<json> body =
      body_text.empty() ? std::optional<json>(json::object()) : parseObject(body_text);

  RpcAnswer a;
  const auto bad = [&](const std::string& why) {
    ++malformed_;
    a = error(kStatusBadRequest, why);
  };
  const auto unavailable = [&](const std::string& what) {
    ++refused_;
    a = error(kStatusServerRefused, what + " is not available in simsoccer" +
                                        (walk_ ? "" : " for this robot (it has no walk)"));
  };
  const auto walkingOnly = [&](const char* what) {
    ++refused_;
    a = error(kStatusStateTransitionFailed, std::string(what) + ": the robot is in " +
                                                modeName(mode_) + " mode, not walking or soccer");
  };
  // A kick's preconditions; false (and the answer made) if one is not met.
  const auto canKick = [&](const char* what) {
    if (!kicks_) {
      ++refused_;
      a = error(kStatusServerRefused,
                std::string(what) + " is not available in simsoccer for this robot (" +
                    (walk_ ? "it has no kick approach" : "it has no walk") + ")");
      return false;
    }
    if (!walking()) {
      walkingOnly(what);
      return false;
    }
    if (down_) {
      ++refused_;
      a = error(kStatusStateTransitionFailed, std::string(what) + ": the robot is down");
      return false;
    }
    return true;
  };
  if (!body) {
    bad("the body is not a JSON object");
  } else {
    switch (static_cast<LocoApi>(static_cast<int>(*api))) {
      case LocoApi::ChangeMode: {
        const std::optional<double> m = number(*body, "mode");
        if (!m || *m != std::floor(*m) || *m < 0 || *m > 4) {
          bad("ChangeMode: \"mode\" must be 0..4 (damping, prepare, walking, custom, soccer)");
        } else {
          const auto mode = static_cast<RobotMode>(static_cast<int>(*m));
          if ((mode == RobotMode::Walking || mode == RobotMode::Soccer) && !walk_) {
            unavailable(std::string("the ") + modeName(mode) + " mode");
          } else {
            const bool was_walking = walking();
            mode_ = mode;
            if (mode_ == RobotMode::Damping || mode_ == RobotMode::Custom) head_.reset();
            if (!(was_walking && walking())) {
              velocity_ = WalkVelocity{};
              visual_kick_ = shoot_ = false;
              down_ = false;  // the walk tells again from its first period
            }
          }
        }
        break;
      }
      case LocoApi::GetMode:
        a.body = json{{"mode", static_cast<int>(mode_)}}.dump();
        break;
      case LocoApi::RotateHead: {
        const std::optional<double> pitch = number(*body, "pitch"), yaw = number(*body, "yaw");
        if (!pitch || !yaw)
          bad("RotateHead: \"pitch\" and \"yaw\" must be numbers (rad)");
        else if (mode_ != RobotMode::Prepare && !walking()) {
          ++refused_;
          a = error(kStatusStateTransitionFailed,
                    std::string("RotateHead: the robot is in ") + modeName(mode_) +
                        " mode; simsoccer turns the head in prepare, walking and soccer mode");
        } else {
          head_ = HeadTarget{*pitch, *yaw};
        }
        break;
      }
      case LocoApi::Move: {
        const std::optional<double> vx = number(*body, "vx"), vy = number(*body, "vy"),
                                    vyaw = number(*body, "vyaw");
        if (!walk_)
          unavailable("Move");
        else if (!vx || !vy || !vyaw || std::abs(*vx) > 10 || std::abs(*vy) > 10 ||
                 std::abs(*vyaw) > 20)
          bad("Move: \"vx\", \"vy\" (m/s) and \"vyaw\" (rad/s) must be numbers of a walk");
        else if (!walking())
          walkingOnly("Move");
        else
          velocity_ = WalkVelocity{*vx, *vy, *vyaw};  // the walk clamps to what it can
        break;
      }
      case LocoApi::GetUp:
      case LocoApi::GetUpWithMode:
        if (!walk_)
          unavailable("Getting up");
        else if (!walking())
          walkingOnly("GetUp");
        // else: the walk's fall detector gets the robot up once it lies still.
        break;
      case LocoApi::LieDown:
        unavailable("Lying down");
        break;
      case LocoApi::Shoot:
        if (canKick("Shoot")) {
          if (visual_kick_) {
            ++refused_;
            a = error(kStatusStateTransitionFailed, "Shoot: the visual kick runs (stop it first)");
          } else {
            shoot_ = true;
            velocity_ = WalkVelocity{};  // it stands after the kick until the next Move
          }
        }
        break;
      case LocoApi::VisualKick: {
        if (!kicks_) {
          canKick("VisualKick");  // answers 501
          break;
        }
        const auto start = body->find("start");
        const std::optional<double> version =
            body->contains("version") ? number(*body, "version") : std::optional<double>(0.0);
        if (start == body->end() || !start->is_boolean()) {
          bad("VisualKick: \"start\" must be true or false");
        } else if (!version || (*version != 0.0 && *version != 1.0)) {
          bad("VisualKick: \"version\" must be 0 (V1) or 1 (V2)");
        } else if (!start->get<bool>()) {
          visual_kick_ = false;  // stopping is always allowed
        } else if (!vision_) {
          ++refused_;
          a = error(kStatusServerRefused,
                    "VisualKick: the robot sees nothing (the scenario's perception is off)");
        } else if (canKick("VisualKick")) {
          visual_kick_ = true;
          ++visual_kick_starts_;
          shoot_ = false;
          visual_kick_version_ = static_cast<int>(*version);
        }
        break;
      }
      case LocoApi::SwitchGait:
        unavailable("SwitchGait");
        break;
      case LocoApi::ResetOdometry:
        ++odometry_resets_;
        break;
      case LocoApi::GetStatus:
      case LocoApi::RotateHeadWithTime:
        ++refused_;
        a = error(kStatusServerRefused,
                  std::string(static_cast<LocoApi>(static_cast<int>(*api)) == LocoApi::GetStatus
                                  ? "GetStatus"
                                  : "RotateHeadWithTime") +
                      " is not available in simsoccer");
        break;
      default:
        if (const char* name = unservedLocoApiName(static_cast<int>(*api))) {
          ++refused_;
          a = error(kStatusServerRefused, std::string(name) + " is not available in simsoccer");
        } else {
          bad("unknown api_id " + std::to_string(static_cast<long long>(*api)));
        }
    }
  }
  a.respond = respond;
  return a;
}

}  // namespace simsoccer::booster

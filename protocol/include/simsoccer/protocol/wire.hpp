// The agent protocol's layout, shared by the simulator and the agents (so an
// agent includes it instead of copying numbers): the command's actuator
// count and order, and the sizes the DDS messages bound. Checked against the
// IDL-generated types at compile time.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "simsoccer_msgs.h"

namespace simsoccer::protocol {

// Entries of a joint command and of a SensorFrame's per-actuator arrays.
inline constexpr std::size_t kActuators = 25;

// The entry order of the DDS command for a Nao: LoLA's joint order (the
// order of the Nao's "Position" and "Stiffness" arrays), hands last. A robot
// description's `actuators:` list gives this order for its model.
inline constexpr std::array<std::string_view, kActuators> kNaoActuatorOrder = {
    "HeadYaw",        "HeadPitch",      "LShoulderPitch", "LShoulderRoll", "LElbowYaw",
    "LElbowRoll",     "LWristYaw",      "LHipYawPitch",   "LHipRoll",      "LHipPitch",
    "LKneePitch",     "LAnklePitch",    "LAnkleRoll",     "RHipRoll",      "RHipPitch",
    "RKneePitch",     "RAnklePitch",    "RAnkleRoll",     "RShoulderPitch", "RShoulderRoll",
    "RElbowYaw",      "RElbowRoll",     "RWristYaw",      "LHand",         "RHand"};

// Entries of a SensorFrame's other arrays.
inline constexpr std::size_t kFsrs = 8;          // L FL FR RL RR, R FL FR RL RR
inline constexpr std::size_t kSonars = 2;        // left, right
inline constexpr std::size_t kSonarEchoes = 10;  // per sonar
inline constexpr std::size_t kTouchSensors = 14; // LoLA's Touch order
// A team message's payload, at most (the SPL's limit for SPLStandardMessage data).
inline constexpr std::size_t kTeamMessageBytes = 128;
// Robots a Perception message lists, at most.
inline constexpr std::size_t kPerceivedRobots = 40;
// Players per team in the GameController's packets.
inline constexpr std::size_t kMaxPlayers = 20;

namespace detail {
template <typename T, std::size_t N>
constexpr std::size_t extent(const T (&)[N]) {
  return N;
}
}  // namespace detail

// A match tells the agents it starts its process id in this environment
// variable: an agent exits when that process does, even if it was killed.
inline constexpr const char* kParentPidVariable = "SIMSOCCER_PARENT_PID";

// The IDL and these constants agree (a changed IDL fails to compile here).
static_assert(detail::extent(simsoccer_msg_SensorFrame{}.position) == kActuators);
static_assert(detail::extent(simsoccer_msg_SensorFrame{}.fsr) == kFsrs);
static_assert(detail::extent(simsoccer_msg_SensorFrame{}.sonar) == kSonars);
static_assert(detail::extent(simsoccer_msg_SensorFrame{}.sonar_echoes) == kSonars * kSonarEchoes);
static_assert(detail::extent(simsoccer_msg_SensorFrame{}.touch) == kTouchSensors);
static_assert(detail::extent(simsoccer_msg_TeamInfo{}.players) == kMaxPlayers);

}  // namespace simsoccer::protocol

// Robot reservation without DDS Security: a match that starts its own agents
// draws a random match secret, derives one key per robot from it, and hands
// each agent only its own robot's key (in its environment, not on its command
// line). A claim carries HMAC-SHA256(key, "claim" | claimant's participant
// GUID), so a participant without the key cannot claim the robot, and a
// claim it overhears is worthless under another GUID. The simulator's
// RobotStatus to the owner carries HMAC-SHA256(key, "simulator" | simulator
// GUID | owner GUID): the agent then knows which participant is the
// simulator and ignores game states, frames and messages from any other.
// What this does not stop (a forged RTPS GUID, reading frames, flooding):
// docs/security.md.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace simsoccer::net {

using MatchSecret = std::array<uint8_t, 32>;
using RobotKey = std::array<uint8_t, 32>;
using Proof = std::array<uint8_t, 32>;  // the size of the proof fields of the messages

// 32 bytes from OpenSSL's random generator; throws if it has no entropy.
MatchSecret newMatchSecret();
// The key of robot (team, player): HMAC-SHA256(secret, "simsoccer robot T P").
RobotKey robotKey(const MatchSecret& secret, int team, int player);
// What an agent holding `key` sends in its JoinRequest.
Proof claimProof(const RobotKey& key, const dds_guid_t& claimant);
// What the simulator sends to the owner in the RobotStatus.
Proof simulatorProof(const RobotKey& key, const dds_guid_t& simulator, const dds_guid_t& owner);
// Constant-time comparison of a received proof (OpenSSL's CRYPTO_memcmp).
bool sameProof(const Proof& expected, const uint8_t* received);

// The environment variable the match runner hands an agent its key in.
inline constexpr const char* kRobotKeyVariable = "SIMSOCCER_ROBOT_KEY";
// 64 lower-case hex digits.
std::string toHex(const RobotKey& key);
// The key from 64 hex digits; nullopt (with `why`) otherwise.
std::optional<RobotKey> keyFromHex(std::string_view hex, std::string* why = nullptr);

}  // namespace simsoccer::net

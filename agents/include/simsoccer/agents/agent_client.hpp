// The client library every agent links: connect to a simulator over DDS,
// claim a robot, then loop: receive its SensorFrame -> compute -> send a
// JointCommand for that tick. Also the GameState, team messages and the
// simulated clock.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "simsoccer/net/dds.hpp"
#include "simsoccer/net/robot_keys.hpp"
#include "simsoccer/protocol/wire.hpp"
#include "simsoccer_msgs.h"

namespace simsoccer::agents {

struct TeamMessageIn {
  int from_player = 0;
  uint64_t tick = 0;
  std::vector<uint8_t> data;
};

// One camera image of this robot (the CameraImage message, data copied).
struct CameraImageIn {
  int camera = 0;     // 0 top, 1 bottom
  uint64_t tick = 0;  // its SensorFrame's tick
  double sim_time = 0.0;
  int encoding = 0;  // 0 YUYV 4:2:2, 1 JPEG
  int width = 0, height = 0;
  std::array<float, 3> position{};     // camera in the field frame, m
  std::array<float, 4> orientation{};  // quaternion x y z w
  std::array<float, 4> intrinsics{};   // fx fy cx cy, px
  std::vector<uint8_t> data;
};

// What the robot's cameras see (the Perception message, copied).
struct PerceivedIn {
  int kind = 0, team = -1;  // kind: 0 ball, 1 goal post, 2 robot
  bool in_view = false;
  float x = 0, y = 0;       // robot frame, m
  double last_seen = -1.0;  // s
};
struct PerceptionIn {
  uint64_t tick = 0;
  double sim_time = 0.0;
  PerceivedIn ball;
  std::array<PerceivedIn, 4> posts;
  std::vector<PerceivedIn> robots;
  std::array<float, 3> self_pose{};  // x, y, yaw in the field frame
};

// A frame's perception as the agent side keeps it (`out.robots` keeps its
// capacity); the tick and time are the frame's.
void perceptionFromMessage(const simsoccer_msg_Perception& m, uint64_t tick, double sim_time,
                           PerceptionIn& out);
// The perception a SensorFrame carries; false when it carries none (the
// scenario turns perception off).
bool perceptionFromFrame(const simsoccer_msg_SensorFrame& f, PerceptionIn& out);

// Which participant is the simulator: the one whose RobotStatus granted this
// agent its robot (with a robot key: whose status also proved it holds that
// key). From then on game states, frames, perception, team messages, images
// and status samples from any other participant are ignored and counted.
class AgentClient {
 public:
  // `key`: the robot's key when the match reserves robots (robot_keys.hpp).
  AgentClient(const net::DomainConfig& dds, int team, int player,
              std::optional<net::RobotKey> key = std::nullopt);
  ~AgentClient();

  int team() const { return team_; }
  int player() const { return player_; }

  // What claim() does when another agent owns the robot.
  enum class IfOwned {
    Refuse,          // returns false as soon as the simulator refuses the request
    WaitForRelease,  // waits for that owner to go away and asks again
  };
  // Sends a join request and waits until the simulator says who owns the
  // robot: true once this agent does; false if no answer came in time, or
  // another agent owns it (IfOwned::Refuse) or still owns it at the timeout.
  // Waiting is what a restarted agent needs: the robot of one that crashed is
  // released only when its DDS lease runs out (net::DomainConfig::lease).
  bool claim(double timeout_seconds, IfOwned if_owned = IfOwned::WaitForRelease);
  // The latest RobotStatus seen for this robot (owner, counters).
  const simsoccer_msg_RobotStatus& status() const { return status_; }
  bool ownsRobot() const;
  // Whether the simulator is known (this agent was granted its robot).
  bool knowsSimulator() const;
  // Readers (the simulator's) this agent's command writer is matched with.
  int commandReadersMatched() const;
  // Samples ignored because another participant than the simulator wrote them.
  uint64_t foreignSamples() const;

  // Waits for this robot's next SensorFrame; false on timeout. Its
  // perception's sightings are held by the client until the next call.
  bool receive(simsoccer_msg_SensorFrame& frame, double timeout_seconds);
  // Alternative to receive(): `handler` is called for every new frame of
  // this robot right in the DDS receive thread (no thread hop: the fastest
  // lockstep round trip). It answers with send(); the caller's thread must
  // not call send() or receive() meanwhile. Pass an empty handler to stop.
  // The frame (its perception's sightings) is valid during the call only.
  using FrameHandler = std::function<void(const simsoccer_msg_SensorFrame&)>;
  void onFrame(FrameHandler handler);
  // Answers the frame of `tick`: 25 positions (rad) and stiffnesses, actuator order.
  void send(uint64_t tick, std::span<const float> position, std::span<const float> stiffness);
  // Raw command, for tests that send malformed ones (wrong sizes, NaN, ...).
  void sendRaw(const simsoccer_msg_JointCommand& command);

  // The latest GameState (false until one arrived).
  bool gameState(simsoccer_msg_GameState& out);
  // Waits until a GameState has arrived (the topic is durable: the last one
  // published reaches a late joiner); false on timeout.
  bool waitForGameState(double timeout_seconds);
  // Team communication: at most 128 bytes, delivered by the simulator to
  // this robot's teammates.
  void sendTeamMessage(std::span<const uint8_t> data);
  std::vector<TeamMessageIn> receiveTeamMessages();

  // Subscribes to this robot's camera images (the scenario must turn cameras
  // on; nothing is sent to an agent that does not subscribe).
  void subscribeImages();
  // The images that arrived since the last call, oldest first; waits up to
  // `timeout_seconds` for the first one if none is there.
  std::vector<CameraImageIn> receiveImages(double timeout_seconds = 0.0);

 private:
  struct Impl;
  int team_, player_;
  std::unique_ptr<Impl> impl_;
  simsoccer_msg_RobotStatus status_{};
  uint32_t serial_ = 0;
  FrameHandler handler_;
  std::optional<net::RobotKey> key_;
  void readStatus();
  // Whether the writer of a sample `reader` took is the simulator (true for
  // any writer until the simulator is known).
  bool fromSimulator(dds_entity_t reader, const dds_sample_info_t& info);
  static void onFrameData(dds_entity_t reader, void* self);
};

}  // namespace simsoccer::agents

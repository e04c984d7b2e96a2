// The Booster Robotics SDK's robot side over DDS, for simulated Booster robots
// (the K1): what a team's unmodified SDK client (the C++ SDK's ChannelFactory,
// B1LocoClient, its Rust and ROS 2 equivalents) talks to on the real robot.
// A command source of the period pipeline.
//
// Each robot gets its own DDS domain (base + its index in the config: the
// SDK's topics carry no robot id, and team code uses domain 0 unless told
// otherwise) with the SDK's topics and registered type names:
//   rt/low_state          LowState_ out, once per control period (a 2 ms
//                         period gives the robot's 500 Hz)
//   rt/joint_ctrl         LowCmd_ in: obeyed in CUSTOM mode, SERIAL command
//                         type, per joint q, dq, tau, kp, kd
//   rt/LocoApiTopicReq    RpcReqMsg_ in (LocoService: modes, head, Move: in
//                         Walking and Soccer simsoccer's own walk drives)
//   rt/LocoApiTopicResp   RpcRespMsg_ out (reliable, transient-local: the
//                         C++ SDK's volatile and the Rust SDK's
//                         transient-local readers both match)
//   rt/fall_down          FallDownState_ out, on change and once a second
//   rt/kick_ball          brain Kick_ in: the visual kick's direction (its
//                         "dir"; the ball is the one the robot's own
//                         perception sees)
//   rt/StereoNetNode/rectified_image   the head camera's images as ROS 2's
//                         sensor_msgs Image_ (YUYV: "yuv422_yuy2") or, with
//                         JPEG cameras, CompressedImage_ on .../compressed,
//                         stamped with the simulation time (attachCameras)
// What a client does wrong (a LowCmd with 21 entries, NaNs, PARALLEL
// commands, garbage JSON) is refused and counted; the robot holds its last
// command. docs/booster.md has the details and the sources.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "simsoccer/booster/loco_service.hpp"
#include "simsoccer/sim/command.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::booster {

struct BoosterRobot {
  world::RobotId robot = 0;
  uint32_t domain = 0;  // the DDS domain its SDK client joins
  RobotMode initial_mode = RobotMode::Prepare;
  // A network namespace (a name under /run/netns) to serve the robot in: its
  // topics go out on that namespace's loopback as domain `namespace_domain`
  // (0: what unmodified team code joins), while `domain` stays the id this
  // process knows the robot's domain by (unique). Needs CAP_SYS_ADMIN.
  std::string network_namespace;
  uint32_t namespace_domain = 0;
  // The robot's motions folder (keyframes and gait.yaml, e.g.
  // configs/motions/booster_k1): simsoccer's walk for the locomotion
  // service's Walking and Soccer modes. Empty: those modes answer 501. With
  // a kick_approach.yaml there (agents::loadKickApproach), Shoot and
  // VisualKick are served too (the visual kick needs the scenario's
  // perception on: without it VisualKick answers 501).
  std::filesystem::path motions;
};

struct EndpointConfig {
  std::vector<BoosterRobot> robots;
  std::filesystem::path dds_config;  // Cyclone XML (empty: Cyclone's default)
  // Lockstep: a robot in CUSTOM mode whose client has sent a LowCmd is
  // waited for (up to answer_timeout s of wall time) to answer each
  // LowState; real time: whatever has arrived is taken.
  bool lockstep = false;
  double answer_timeout = 0.5;
  int unresponsive_after = 3;       // misses in a row before a client is no longer waited for
  double fall_down_interval = 1.0;  // s of simulation between unchanged fall_down samples
  // The ROS 2 topic (DDS name) of the robot's first camera; Booster's vision
  // stack publishes its rectified head-camera image here.
  std::string image_topic = "rt/StereoNetNode/rectified_image";
};

struct RobotBoosterStats {
  RobotMode mode = RobotMode::Prepare;  // the locomotion service's, when asked
  uint64_t states_sent = 0;             // LowState_ samples
  uint64_t commands = 0;                // LowCmd_ samples received
  uint64_t applied = 0;                 // periods a LowCmd drove the robot (CUSTOM)
  uint64_t ignored = 0;                 // well-formed LowCmds outside CUSTOM mode
  uint64_t refused = 0;                 // LowCmds refused (size, PARALLEL; NaN, range: the gate)
  uint64_t missed = 0;                  // lockstep periods without a LowCmd in time
  uint64_t late = 0;                    // lockstep: LowCmds that came after their period (dropped)
  uint64_t requests = 0, requests_refused = 0, requests_malformed = 0;
  uint64_t images = 0;                // camera images published
  uint64_t walk_starts = 0;           // times simsoccer's walk (re)started: each entry into WALKING
                                      // or SOCCER from another mode
  uint64_t kicks = 0;                 // kicks the walk made (Shoot, the visual kick)
  uint64_t falls = 0, get_ups = 0;    // the walk's fall detector's: falls, get-ups that stood
  uint64_t kick_targets = 0;          // rt/kick_ball samples received
  uint64_t kick_targets_refused = 0;  // of them with a dir that is not an angle (NaN, beyond 2π)
};

// The period (s) simsoccer's walk runs at for the locomotion service: the
// matches' control period, which the built-in agents' walk and kick were
// tuned at, rounded to whole control periods (at least one: a K1's 2 ms
// period runs it every fifth, 3 ms every third, i.e. 9 ms; 20 ms every one).
// Its targets act one walk period after the state they were computed from,
// as the agents' do in matches.
inline constexpr double kWalkPeriod = 0.010;

class Endpoint : public sim::CommandSource {
 public:
  // Joins every robot's domain. Throws std::invalid_argument for a robot
  // index out of range or served twice, or two robots on one domain,
  // std::out_of_range for a robot model without a stand pose, engine::ConfigError
  // for a bad motions folder (a robot's `motions`), net::DdsError
  // if DDS fails.
  Endpoint(const world::World& world, EndpointConfig config);
  ~Endpoint() override;
  Endpoint(const Endpoint&) = delete;
  Endpoint& operator=(const Endpoint&) = delete;

  // Publishes the served robots' first-camera images as ROS 2 image messages
  // (the simulation's cameras must be on; before its first period).
  void attachCameras(sim::Simulation& simulation);

  void observe(const sim::Observation& o) override;
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override;

  const EndpointConfig& config() const { return config_; }
  // Per robot of the config, in its order.
  RobotBoosterStats stats(std::size_t i) const;
  // Whether robot i's rt/low_state has a reader matched (a client is there).
  bool clientConnected(std::size_t i) const;

 private:
  struct Robot;
  void answerRequests(Robot& r);
  // rt/kick_ball: the visual kick's direction.
  void takeKickTargets(Robot& r);
  void publishImage(const world::CameraImage& image);
  // rt/odometer_state and rt/head_pose from the world's state.
  void publishPoses(Robot& r, const world::World& w);
  // Walking and Soccer: the walk's targets from the frame just observed,
  // acting from period `acts_at`.
  void walkTargets(Robot& r, const world::SensorFrame& frame, uint64_t acts_at);
  // The command of robot r's mode outside CUSTOM (prepare: stand; damping;
  // walking and soccer: the walk's targets).
  std::optional<sim::RobotCommand> modeCommand(Robot& r, sim::CommandGate& gate) const;
  const world::World& world_;
  EndpointConfig config_;
  std::vector<std::unique_ptr<Robot>> robots_;
  int32_t waitset_ = 0;   // a DDS waitset on every robot's commands (lockstep)
  double time_ = 0.0;     // the simulation time of the last observation
  uint64_t acts_at_ = 0;  // the period the commands collected next act in
  // The walk's period: kWalkPeriod in whole control periods (at least one).
  uint64_t walk_periods_ = 1;
  double walk_dt_ = 0.01;
};

}  // namespace simsoccer::booster

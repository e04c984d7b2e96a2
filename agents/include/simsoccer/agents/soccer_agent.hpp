// One robot's soccer agent: the behaviour and the motion layer run on one
// control period's inputs (its sensor frame, perception, the GameState,
// teammates' messages), answering with joint targets and, when it is time,
// a team message. simsoccer-agent runs it over DDS; benches run the same
// class in-process, so both play identically.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/agents/motion/motion_controller.hpp"

namespace simsoccer::agents {

// A motion controller with the keyframe motions of `motions_dir`
// (get_up_front.yaml, get_up_back.yaml, block.yaml, dive_left.yaml, dive_right.yaml,
// sit_down.yaml, stand_up.yaml) and its gait.yaml if it has one (gait.hpp).
MotionController loadMotionController(const robots::RobotModel& model,
                                      const std::filesystem::path& motions_dir,
                                      const FallDetectorParameters& fall = {});

// A robot's motions folder under `root` (configs/motions): root/<model name>
// where that folder exists (configs/motions/booster_k1), else root itself
// (the Nao's motions).
std::filesystem::path motionsFolder(const std::filesystem::path& root,
                                    const robots::RobotModel& model);

struct SoccerAgentSetup {
  int team = 0, team_number = 1, player = 1;
  Role role = Role::Auto;
  uint64_t seed = 1;
  bool get_up = true;  // see FallDetectorParameters::get_up
};

class SoccerAgent {
 public:
  SoccerAgent(const robots::RobotModel& model, const BehaviourConfig& config,
              const fields::FieldModel& field, const std::filesystem::path& motions_dir,
              const SoccerAgentSetup& setup);

  void receive(const TeamMessageIn& message, double time) { behaviour_.receive(message, time); }
  // One period: `perception` and `game` may be null (none this period / ever).
  // Writes 25 targets and stiffnesses (actuator order); returns the team
  // message to send, if any.
  std::optional<std::vector<uint8_t>> step(double time, double dt, const MotionSensors& sensors,
                                           const PerceptionIn* perception,
                                           const simsoccer_msg_GameState* game,
                                           std::span<float> position, std::span<float> stiffness);

  const MotionController& motion() const { return motion_; }
  const SoccerBehaviour& behaviour() const { return behaviour_; }

 private:
  SoccerBehaviour behaviour_;
  MotionController motion_;
};

}  // namespace simsoccer::agents

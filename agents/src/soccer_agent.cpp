#include "simsoccer/agents/soccer_agent.hpp"

#include "simsoccer/agents/motion/gait.hpp"

namespace simsoccer::agents {

MotionController loadMotionController(const robots::RobotModel& model,
                                      const std::filesystem::path& motions_dir,
                                      const FallDetectorParameters& fall) {
  const auto load = [&](const char* name) {
    return loadKeyframeMotion(motions_dir / (std::string(name) + ".yaml"), model);
  };
  const Gait gait = loadGaitIn(motions_dir);
  return MotionController(
      model,
      KeyframeMotions{load("get_up_front"), load("get_up_back"), load("block"), load("dive_left"),
                      load("dive_right"), load("sit_down"), load("stand_up")},
      gait.walk, gait.kick, fall);
}

std::filesystem::path motionsFolder(const std::filesystem::path& root,
                                    const robots::RobotModel& model) {
  const std::filesystem::path own = root / model.name;
  return std::filesystem::is_directory(own) ? own : root;
}

namespace {
FallDetectorParameters fallParameters(bool get_up) {
  FallDetectorParameters f;
  f.get_up = get_up;
  return f;
}
}  // namespace

SoccerAgent::SoccerAgent(const robots::RobotModel& model, const BehaviourConfig& config,
                         const fields::FieldModel& field, const std::filesystem::path& motions_dir,
                         const SoccerAgentSetup& setup)
    : behaviour_(config, field, setup.team, setup.team_number, setup.player, setup.role,
                 setup.seed),
      motion_(loadMotionController(model, motions_dir, fallParameters(setup.get_up))) {}

std::optional<std::vector<uint8_t>> SoccerAgent::step(
    double time, double dt, const MotionSensors& sensors, const PerceptionIn* perception,
    const simsoccer_msg_GameState* game, std::span<float> position, std::span<float> stiffness) {
  SoccerBehaviour::Input in;
  in.time = time;
  in.perception = perception;
  in.game = game;
  in.motion = motion_.state();
  const Eigen::Vector2d feet = motion_.feetCentre(sensors);
  in.feet = {feet.x(), feet.y()};
  const MotionRequest request = behaviour_.update(in);
  if (behaviour_.takeMotionRestart()) motion_.restart();
  auto message = behaviour_.outgoing(in);
  motion_.update(dt, sensors, request, position, stiffness);
  return message;
}

}  // namespace simsoccer::agents

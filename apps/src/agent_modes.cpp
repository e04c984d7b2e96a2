#include "agent_modes.hpp"

#include <cmath>
#include <numbers>

#include "cli.hpp"
#include "simsoccer/agents/motion/gait.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::apps {

SimpleModes::SimpleModes(const robots::RobotModel& model, const std::filesystem::path& motions,
                         std::string mode, double vx, double vy, double turn)
    : model_(model),
      mode_(std::move(mode)),
      vx_(vx),
      vy_(vy),
      turn_(turn),
      position_(protocol::kActuators, 0.0f),
      stiffness_(protocol::kActuators, 1.0f),
      walk_(model, agents::loadGaitIn(motions).walk),
      targets_(model.pose("stand")) {
  const auto& stand = model.pose("stand");
  for (size_t a = 0; a < model.actuators.size() && a < protocol::kActuators; ++a) {
    const auto& act = model.actuators[a];
    if (act.kind == robots::Actuator::Kind::Joint)
      position_[a] = static_cast<float>(stand[static_cast<size_t>(act.index)]);
    if (act.name == "HeadPitch") head_pitch_ = static_cast<int>(a);
  }
}

void SimpleModes::answer(const simsoccer_msg_SensorFrame& frame, agents::AgentClient& client,
                         int team, int player) {
  if (mode_ == "walk") {
    if (start_time_ < 0) start_time_ = last_time_ = frame.sim_time;
    const double t = frame.sim_time - start_time_, dt = frame.sim_time - last_time_;
    last_time_ = frame.sim_time;
    if (t < 1.0) {  // ease from the stand pose into the walk's stance, then hold it
      walk_.easeIn(model_.pose("stand"), t, targets_);
    } else {
      walk_.setVelocity(vx_, vy_, turn_);
      walk_.update(dt > 0 ? dt : 0.01,
                   {engine::Vec3(frame.gyroscope[0], frame.gyroscope[1], frame.gyroscope[2]),
                    frame.angles[0], frame.angles[2]},
                   targets_);
    }
    for (size_t a = 0; a < model_.actuators.size() && a < protocol::kActuators; ++a)
      if (model_.actuators[a].kind == robots::Actuator::Kind::Joint)
        position_[a] = static_cast<float>(targets_[static_cast<size_t>(model_.actuators[a].index)]);
  } else if (head_pitch_ >= 0) {
    position_[static_cast<size_t>(head_pitch_)] =
        static_cast<float>(0.2 * std::sin(2.0 * std::numbers::pi * 0.5 * frame.sim_time));
  }
  if (mode_ == "garbage") {
    // One invalid command of each kind in turn, then the valid answer.
    simsoccer_msg_JointCommand bad{};
    bad.team = static_cast<uint8_t>(team);
    bad.player = static_cast<uint8_t>(player);
    bad.tick = frame.tick;
    std::vector<float> p = position_, k = stiffness_;
    bad.position._buffer = p.data();
    bad.position._length = bad.position._maximum = protocol::kActuators;
    bad.stiffness._buffer = k.data();
    bad.stiffness._length = bad.stiffness._maximum = protocol::kActuators;
    switch (garbage_++ % 5) {
      case 0:
        p[3] = std::nanf("");
        break;  // NaN
      case 1:
        bad.position._length = protocol::kActuators - 1;
        break;  // wrong count
      case 2:
        bad.tick = frame.tick > 0 ? frame.tick - 1 : frame.tick + 7;
        break;  // stale
      case 3:
        bad.tick = frame.tick + 5;
        break;  // future
      case 4:
        k[10] = 3.0f;
        break;  // stiffness out of range
    }
    client.sendRaw(bad);
  }
  client.send(frame.tick, position_, stiffness_);
}

}  // namespace simsoccer::apps

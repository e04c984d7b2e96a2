// What agents and the command check take from others: the agent's behaviour
// config and a keyframe motion file (YAML), a teammate's team message (the
// 20-byte layout), and a joint command's positions and stiffnesses as a DDS
// sample brings them (any count of any floats) through sim::CommandGate, the
// one check every command source goes through. The first byte picks.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <vector>

#include "fuzz_input.hpp"
#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/agents/motion/keyframe_motion.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/sim/command.hpp"
#include "simsoccer/world/scenario.hpp"
#include "simsoccer/world/world.hpp"

namespace {

using namespace simsoccer;

const robots::RobotModel& model() {
  static const robots::RobotModel m =
      robots::loadRobotModel(std::filesystem::path(SIMSOCCER_SOURCE_DIR) / "robots/nao_v6_h25.yaml");
  return m;
}

sim::CommandGate& gate() {
  static world::World w(world::loadScenario(std::filesystem::path(SIMSOCCER_SOURCE_DIR) /
                                            "configs/scenarios/match_2v2.yaml"));
  static sim::CommandGate g(w, 0.05);
  return g;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t* body = data + 1;
  const size_t n = size - 1;
  try {
    switch (data[0] % 4) {
      case 0:
        agents::loadBehaviourConfig(fuzz::asFile(body, n, "agent.yaml"));
        break;
      case 1:
        agents::loadKeyframeMotion(fuzz::asFile(body, n, "motion.yaml"), model());
        break;
      case 2: {
        const auto d = agents::decodeTeamMessage(std::vector<uint8_t>(body, body + n));
        // A decoded message is finite and of a known role, whatever the bytes.
        if (d && (!std::isfinite(d->x) || !std::isfinite(d->cost) ||
                  static_cast<int>(d->role) > 6))
          std::abort();
        break;
      }
      default: {
        // Positions then stiffnesses, each up to the 25 a sample may carry.
        std::vector<float> values(n / sizeof(float));
        if (!values.empty()) std::memcpy(values.data(), body, values.size() * sizeof(float));
        const size_t split = values.empty() ? 0 : body[0] % (values.size() + 1);
        const std::span<const float> all(values);
        const auto checked = gate().check(0, all.first(std::min<size_t>(split, 25)),
                                          all.subspan(split).first(std::min<size_t>(
                                              values.size() - split, 25)));
        // What the gate lets through is finite and within the stiffness range.
        if (checked)
          for (size_t k = 0; k < checked->position.size(); ++k)
            if (!std::isfinite(checked->position[k]) || !(checked->stiffness[k] >= 0.0) ||
                !(checked->stiffness[k] <= 1.0))
              std::abort();
        break;
      }
    }
  } catch (const std::exception&) {
  }
  return 0;
}

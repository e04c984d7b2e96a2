// The YAML loaders on any file: the rule book, the robot model, the field,
// the scenario (with the robot and field files it names), the match config.
// The first byte picks the loader. engine::ConfigError (and yaml-cpp's own
// exceptions, which the loaders turn into errors naming the file) are the
// expected refusals.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz_input.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/world/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace simsoccer;
  if (size == 0) return 0;
  const auto file = fuzz::asFile(data + 1, size - 1, "config.yaml");
  try {
    switch (data[0] % 5) {
      case 0: referee::loadRuleBook(file); break;
      case 1: robots::loadRobotModel(file); break;
      case 2: fields::loadFieldModel(file); break;
      case 3: world::loadScenario(file); break;
      default: match::loadMatchConfig(file); break;
    }
  } catch (const std::exception&) {
  }
  return 0;
}

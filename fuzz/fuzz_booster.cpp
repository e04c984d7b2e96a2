// What a Booster SDK client sends a simulated robot: a locomotion RPC request
// (its JSON header and body, any bytes) into booster::LocoService, and a
// LowCmd's per-joint values (any count of any floats: q, dq, tau, kp, kd)
// through sim::CommandGate::checkServo on a K1. The first byte picks.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string_view>
#include <vector>

#include "simsoccer/booster/loco_service.hpp"
#include "simsoccer/sim/command.hpp"
#include "simsoccer/world/world.hpp"

namespace {

using namespace simsoccer;

sim::CommandGate& gate() {
  static world::World w([] {
    world::Scenario s = world::loadScenario(std::filesystem::path(SIMSOCCER_SOURCE_DIR) /
                                            "configs/scenarios/k1_3v3.yaml");
    s.robots.resize(1);
    return s;
  }());
  static sim::CommandGate g(w, 0.05);
  return g;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const uint8_t* body = data + 2;
  const size_t n = size - 2;
  // Neither the service nor the gate may throw: no catch (an exception is a finding).
  {
    if (data[0] % 2 == 0) {
      // Header, then body, split where the second byte says.
      const std::string_view all(reinterpret_cast<const char*>(body), n);
      const size_t split = n == 0 ? 0 : data[1] % (n + 1);
      // Bit 1 of the first byte: a robot with simsoccer's walk and kicks (the K1), which
      // starts walking.
      const bool walk = data[0] & 2;
      booster::LocoService service(walk ? booster::RobotMode::Soccer : booster::RobotMode::Prepare,
                                   {walk, walk, walk});
      for (int k = 0; k < 3; ++k) {  // thrice: later ones see the earlier ones' state
        if (k == 2) {
          service.setDown(data[0] & 4);
          if ((data[0] & 4) && service.visualKick()) std::abort();  // a fall ends it
        }
        const booster::RpcAnswer a = service.handle(all.substr(0, split), all.substr(split));
        // Only the SDK's codes; a JSON body; never a mode or a kick simsoccer cannot run.
        if (a.status != booster::kStatusSuccess && a.status != booster::kStatusBadRequest &&
            a.status != booster::kStatusServerRefused &&
            a.status != booster::kStatusStateTransitionFailed)
          std::abort();
        if (!a.body.empty() && !nlohmann::json::accept(a.body)) std::abort();
        if (!walk && (service.walking() || service.visualKick() || service.takeShoot()))
          std::abort();
        if (service.visualKick() && !service.walking()) std::abort();
      }
    } else {
      // Five arrays of equal length (the second byte shortens the last).
      std::vector<float> values(n / sizeof(float));
      if (!values.empty()) std::memcpy(values.data(), body, values.size() * sizeof(float));
      const size_t each = values.size() / 5;
      const std::span<const float> all(values);
      sim::CommandGate::ServoSpans c{all.first(each), all.subspan(each).first(each),
                                     all.subspan(2 * each).first(each),
                                     all.subspan(3 * each).first(each),
                                     all.subspan(4 * each).first(each - (data[1] % 2 && each))};
      const auto checked = gate().checkServo(0, c);
      // What passes is finite, its gains non-negative.
      if (checked)
        for (size_t k = 0; k < each; ++k)
          if (!std::isfinite(checked->position[k]) || !std::isfinite(checked->torque[k]) ||
              !(checked->kp[k] >= 0.0) || !(checked->kd[k] >= 0.0))
            std::abort();
    }
  }
  return 0;
}

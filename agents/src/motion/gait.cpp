#include "simsoccer/agents/motion/gait.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::agents {
namespace {

using engine::ConfigNode;

// What a parameter may be: any finite number, >= 0, > 0, or a share in (0, 1].
enum class Range { Any, NonNegative, Positive, Share };

template <class Parameters>
struct Field {
  const char* name;
  double Parameters::*member;
  Range range;
};

const char* rangeProblem(double v, Range range) {
  if (!std::isfinite(v)) return "must be a finite number";
  switch (range) {
    case Range::Any:
      return nullptr;
    case Range::NonNegative:
      return v >= 0.0 ? nullptr : "must be >= 0";
    case Range::Positive:
      return v > 0.0 ? nullptr : "must be > 0";
    case Range::Share:
      return v > 0.0 && v <= 1.0 ? nullptr : "must be a share in (0, 1]";
  }
  return nullptr;
}

template <class Parameters>
void check(const char* group, const std::vector<Field<Parameters>>& fields, const Parameters& p) {
  for (const auto& f : fields)
    if (const char* problem = rangeProblem(p.*(f.member), f.range))
      throw std::invalid_argument(std::string(group) + "." + f.name + ": " + problem);
}

// Below the walk's own limit, turning on the spot could not keep up with a turn the walk
// accepts (setVelocity caps it by max_turn): the heading hold's error would grow for ever.
const char* turnOnSpotProblem(const WalkParameters& p) {
  return p.max_turn_on_spot > 0.0 && p.max_turn_on_spot < p.max_turn
             ? "must be 0 (as walking) or at least max_turn"
             : nullptr;
}

template <class Parameters>
void read(const ConfigNode& map, const std::vector<Field<Parameters>>& fields, Parameters& p) {
  if (!map.raw().IsMap()) map.fail("expected a mapping of parameter names to numbers");
  for (const auto& [key, value] : map.entries()) {
    const Field<Parameters>* field = nullptr;
    for (const auto& f : fields)
      if (key == f.name) field = &f;
    if (!field) {
      std::string known;
      for (const auto& f : fields) known += (known.empty() ? "" : ", ") + std::string(f.name);
      value.fail("unknown parameter (known: " + known + ")");
    }
    p.*(field->member) = field->range == Range::Positive || field->range == Range::Share
                             ? value.positive()
                         : field->range == Range::NonNegative ? value.nonNegative()
                                                              : value.number();
    if (field->range == Range::Share && p.*(field->member) > 1.0)
      value.fail("must be a share in (0, 1]");
    if (!std::isfinite(p.*(field->member))) value.fail("must be a finite number");
  }
}

const std::vector<Field<WalkParameters>>& walkFields() {
  using W = WalkParameters;
  static const std::vector<Field<W>> f{
      {"step_period", &W::step_period, Range::Positive},
      {"foot_lift", &W::foot_lift, Range::NonNegative},
      {"ankle_height", &W::ankle_height, Range::Positive},
      {"step_width", &W::step_width, Range::Positive},
      {"sway", &W::sway, Range::NonNegative},
      {"torso_lean", &W::torso_lean, Range::Any},
      {"torso_offset", &W::torso_offset, Range::Any},
      {"forward_scale", &W::forward_scale, Range::Positive},
      {"max_forward", &W::max_forward, Range::Positive},
      {"max_backward", &W::max_backward, Range::Positive},
      {"max_side", &W::max_side, Range::Positive},
      {"max_turn", &W::max_turn, Range::Positive},
      {"max_accel", &W::max_accel, Range::Positive},
      {"max_side_accel", &W::max_side_accel, Range::Positive},
      {"max_turn_accel", &W::max_turn_accel, Range::Positive},
      {"max_turn_on_spot", &W::max_turn_on_spot, Range::NonNegative},
      {"max_turn_accel_on_spot", &W::max_turn_accel_on_spot, Range::NonNegative},
      {"hip_roll_compensation", &W::hip_roll_compensation, Range::Any},
      {"heading_gain", &W::heading_gain, Range::NonNegative},
      {"stop_heading_tolerance", &W::stop_heading_tolerance, Range::NonNegative},
      {"start_shift_time", &W::start_shift_time, Range::NonNegative},
      {"ankle_pitch_gyro", &W::ankle_pitch_gyro, Range::Any},
      {"ankle_roll_gyro", &W::ankle_roll_gyro, Range::Any},
      {"gyro_smoothing", &W::gyro_smoothing, Range::Share},
      {"support_lean", &W::support_lean, Range::NonNegative},
      {"max_support_hold", &W::max_support_hold, Range::NonNegative},
      {"stiffness", &W::stiffness, Range::Positive}};
  return f;
}

const std::vector<Field<KickParameters>>& kickFields() {
  using K = KickParameters;
  static const std::vector<Field<K>> f{
      {"shift", &K::shift, Range::Any},
      {"lift", &K::lift, Range::NonNegative},
      {"draw_back", &K::draw_back, Range::Any},
      {"reach", &K::reach, Range::Any},
      {"shift_time", &K::shift_time, Range::Positive},
      {"lift_time", &K::lift_time, Range::Positive},
      {"swing_time", &K::swing_time, Range::Positive},
      {"retract_time", &K::retract_time, Range::Positive},
      {"lower_time", &K::lower_time, Range::Positive},
      {"return_time", &K::return_time, Range::Positive},
      {"settle_time", &K::settle_time, Range::NonNegative},
      {"ready_time", &K::ready_time, Range::NonNegative},
      {"calm_rate", &K::calm_rate, Range::NonNegative},
      {"calm_time", &K::calm_time, Range::NonNegative},
      {"calm_wait", &K::calm_wait, Range::NonNegative},
      {"hip_roll_compensation", &K::hip_roll_compensation, Range::Any},
      {"swing_height", &K::swing_height, Range::Any},
      {"swing_out", &K::swing_out, Range::Any},
      {"tilt_gain", &K::tilt_gain, Range::NonNegative},
      {"tilt_deadband", &K::tilt_deadband, Range::NonNegative}};
  return f;
}

}  // namespace

Gait loadGait(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"walk", "kick"});
  Gait g;
  if (auto w = root.optional("walk")) {
    read(*w, walkFields(), g.walk);
    if (const char* problem = turnOnSpotProblem(g.walk)) w->failKey("max_turn_on_spot", problem);
  }
  if (auto k = root.optional("kick")) read(*k, kickFields(), g.kick);
  return g;
}

void checkGait(const Gait& g) {
  check("walk", walkFields(), g.walk);
  check("kick", kickFields(), g.kick);
  if (const char* problem = turnOnSpotProblem(g.walk))
    throw std::invalid_argument(std::string("walk.max_turn_on_spot: ") + problem);
}

Gait loadGaitIn(const std::filesystem::path& motions_dir) {
  const std::filesystem::path file = motions_dir / "gait.yaml";
  return std::filesystem::exists(file) ? loadGait(file) : Gait{};
}

}  // namespace simsoccer::agents

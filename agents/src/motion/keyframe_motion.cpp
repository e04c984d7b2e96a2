#include "simsoccer/agents/motion/keyframe_motion.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "simsoccer/engine/config.hpp"
#include "smoothstep.hpp"

namespace simsoccer::agents {

namespace {

// An optional `key: one of choices` (default the first): the index of the value; any
// other value is an error naming the key and the choices.
size_t choice(const engine::ConfigNode& root, const std::string& key,
              const std::vector<std::string>& choices) {
  const auto node = root.optional(key);
  if (!node) return 0;
  const std::string v = node->string();
  const auto it = std::find(choices.begin(), choices.end(), v);
  if (it == choices.end()) {
    std::string list;
    for (size_t i = 0; i < choices.size(); ++i)
      list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
    node->fail("must be " + list);
  }
  return static_cast<size_t>(it - choices.begin());
}

}  // namespace

double KeyframeMotion::duration() const {
  double d = 0.0;
  for (const Keyframe& f : frames) d += f.duration;
  return d;
}

KeyframeMotion loadKeyframeMotion(const std::filesystem::path& file,
                                  const robots::RobotModel& model) {
  const engine::ConfigNode root = engine::ConfigNode::loadFile(file);
  root.allowOnly({"motion", "interpolation", "ends", "frames"});
  KeyframeMotion m;
  m.name = root["motion"].string();
  // In the enums' order.
  m.interpolation = static_cast<KeyframeMotion::Interpolation>(
      choice(root, "interpolation", {"smooth", "linear"}));
  m.ends = static_cast<KeyframeMotion::Ends>(choice(root, "ends", {"standing", "front", "back"}));
  const auto& joints = model.body->joints;
  std::vector<double> q = model.pose("stand");
  for (const engine::ConfigNode& item : root["frames"].items()) {
    item.allowOnly({"duration", "stiffness", "pose", "joints"});
    Keyframe f;
    f.duration = item["duration"].positive();
    f.stiffness = item.number("stiffness", 1.0);
    if (f.stiffness < 0.0 || f.stiffness > 1.0) item["stiffness"].fail("must be within 0..1");
    if (auto pose = item.optional("pose")) {
      const std::string name = pose->string();
      if (!model.poses.count(name))
        pose->fail("robot model '" + model.name + "' has no pose '" + name + "'");
      q = model.pose(name);
    }
    if (auto set = item.optional("joints")) {
      for (const auto& [name, value] : set->entries()) {
        const int j = model.body->jointIndex(name);
        if (j < 0)
          set->failKey(name, "robot model '" + model.name + "' has no joint '" + name + "'");
        const auto& joint = joints[static_cast<size_t>(j)];
        if (joint.mimic_of >= 0)
          set->failKey(name, "a mimic joint follows its master: set that one");
        const double v = value.number();
        if (v < joint.lower - 1e-6 || v > joint.upper + 1e-6)
          set->failKey(name, "beyond the joint's limits [" + engine::formatNumber(joint.lower) +
                                 ", " + engine::formatNumber(joint.upper) + "]");
        q[static_cast<size_t>(j)] = v;
      }
    }
    model.body->applyMimic(q);
    f.position = q;
    m.frames.push_back(std::move(f));
  }
  if (m.frames.empty()) root["frames"].fail("needs at least one frame");
  return m;
}

void KeyframePlayer::start(const KeyframeMotion& motion, const std::vector<double>& measured) {
  motion_ = &motion;
  last_ = &motion;
  from_ = measured;
  t_ = 0.0;
}

void KeyframePlayer::update(double dt, std::vector<double>& targets, double& stiffness) {
  if (!motion_) return;
  t_ += dt;
  double begin = 0.0;
  const std::vector<double>* prev = &from_;
  for (const Keyframe& f : motion_->frames) {
    if (t_ < begin + f.duration) {
      const double s = (t_ - begin) / f.duration;
      const double w =
          motion_->interpolation == KeyframeMotion::Interpolation::Linear ? s : smoothstep(s);
      for (size_t j = 0; j < targets.size() && j < f.position.size(); ++j)
        targets[j] = (*prev)[j] + w * (f.position[j] - (*prev)[j]);
      stiffness = f.stiffness;
      return;
    }
    begin += f.duration;
    prev = &f.position;
  }
  const Keyframe& last = motion_->frames.back();
  targets.assign(last.position.begin(), last.position.end());
  stiffness = last.stiffness;
  motion_ = nullptr;
}

}  // namespace simsoccer::agents

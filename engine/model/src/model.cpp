#include "simsoccer/engine/model.hpp"

#include <stdexcept>
#include <string>

namespace simsoccer::engine {

int ArticulatedModel::linkIndex(const std::string& link_name) const {
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].name == link_name) return static_cast<int>(i);
  return -1;
}

int ArticulatedModel::jointIndex(const std::string& joint_name) const {
  for (size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == joint_name) return static_cast<int>(i);
  return -1;
}

void ArticulatedModel::applyMimic(std::span<double> q) const {
  if (q.size() != joints.size())
    throw std::invalid_argument("applyMimic: " + std::to_string(q.size()) +
                                " joint positions for " + std::to_string(joints.size()) +
                                " joints");
  for (size_t j = 0; j < q.size(); ++j)
    if (joints[j].mimic_of >= 0)
      q[j] = joints[j].mimic_multiplier * q[static_cast<size_t>(joints[j].mimic_of)];
}

double ArticulatedModel::totalMass() const {
  double m = 0.0;
  for (const Link& l : links) m += l.mass;
  return m;
}

Vec3 ArticulatedModel::centreOfMass(std::span<const Pose> link_frames) const {
  if (link_frames.size() != links.size())
    throw std::invalid_argument("centreOfMass: " + std::to_string(link_frames.size()) +
                                " link frames for " + std::to_string(links.size()) + " links");
  Vec3 sum = Vec3::Zero();
  for (size_t l = 0; l < links.size(); ++l) sum += links[l].mass * (link_frames[l] * links[l].com);
  return sum / totalMass();
}

std::vector<Pose> ArticulatedModel::linkFramesAt(const std::vector<double>& q) const {
  std::vector<Pose> frames(links.size(), Pose::Identity());
  for (size_t j = 0; j < joints.size(); ++j) {
    const Joint& joint = joints[j];
    const double angle = j < q.size() ? q[j] : 0.0;
    Pose local = Pose::Identity();
    local.translate(joint.origin);
    local.rotate(Eigen::AngleAxisd(angle, joint.axis));
    frames[static_cast<size_t>(joint.child_link)] =
        frames[static_cast<size_t>(joint.parent_link)] * local;
  }
  return frames;
}

}  // namespace simsoccer::engine

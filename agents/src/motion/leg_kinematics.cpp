#include "simsoccer/agents/motion/leg_kinematics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace simsoccer::agents {

namespace {

constexpr const char* kJointNames[6] = {"HipYawPitch", "HipRoll",    "HipPitch",
                                        "KneePitch",   "AnklePitch", "AnkleRoll"};

// Orientation error as a rotation vector: the rotation taking `current` to `target`.
Vec3 rotationError(const Eigen::Matrix3d& target, const Eigen::Matrix3d& current) {
  const Eigen::AngleAxisd aa(target * current.transpose());
  return aa.angle() * aa.axis();
}

}  // namespace

LegKinematics::LegKinematics(const robots::RobotModel& model) {
  const auto& body = *model.body;
  for (int side = 0; side < 2; ++side) {
    Chain& c = legs_[static_cast<size_t>(side)];
    const std::string prefix = side == 0 ? "L" : "R";
    for (int i = 0; i < 6; ++i) {
      const std::string name = prefix + kJointNames[i];
      const int j = body.jointIndex(name);
      if (j < 0)
        throw std::invalid_argument("leg kinematics: robot model " + model.name + " has no joint " +
                                    name);
      const engine::Joint& joint = body.joints[static_cast<size_t>(j)];
      if (i > 0 && joint.parent_link != body.joints[static_cast<size_t>(c.joint[i - 1])].child_link)
        throw std::invalid_argument("leg kinematics: " + name + " does not follow " + prefix +
                                    kJointNames[i - 1]);
      c.joint[i] = j;
      c.origin[i] = joint.origin;
      c.axis[i] = joint.axis.normalized();
      c.lower[i] = joint.lower;
      c.upper[i] = joint.upper;
    }
  }
  // The sole: the lowest point of the foot's collision shapes in its frame.
  const int foot = body.joints[static_cast<size_t>(legs_[0].joint[5])].child_link;
  for (const engine::Shape& s : body.links[static_cast<size_t>(foot)].shapes) {
    double bottom = s.pose.translation().z();
    if (s.type == engine::ShapeType::Box) bottom -= 0.5 * s.extents.z();
    if (s.type == engine::ShapeType::Sphere) bottom -= s.radius;
    sole_depth_ = std::max(sole_depth_, -bottom);
  }
}

Pose LegKinematics::forward(Leg leg, const LegAngles& q) const {
  const Chain& c = legs_[static_cast<size_t>(leg)];
  Pose t = Pose::Identity();
  for (int i = 0; i < 6; ++i) {
    t.translate(c.origin[i]);
    t.rotate(Eigen::AngleAxisd(q[i], c.axis[i]));
  }
  return t;
}

LegSolution LegKinematics::inverse(const Pose& left_foot, const Pose& right_foot,
                                   const LegSolution* start) const {
  // Both legs at once: 11 unknowns (the shared HipYawPitch and five joints
  // per leg) for 12 equations (two foot poses), damped least squares with
  // joints at a limit they push against taken out; restarts from other
  // knee bends if it stalls. Positions weigh more than orientations (0.05 m
  // per rad), so when the feet's yaws disagree the positions are kept.
  // Weights (m per rad) of the orientation error, in the target foot's
  // frame: a foot must land flat (roll, pitch), its yaw may give where the
  // shared HipYawPitch cannot serve both feet.
  const double w = 0.05;
  const Eigen::Vector3d w_axes(0.2, 0.2, 0.03);
  const std::array<const Pose*, 2> targets{&left_foot, &right_foot};
  auto run = [&](std::array<LegAngles, 2> q, double& pe, double& oe) {
    std::array<Vec3, 2> pos_err{}, rot_err{};
    for (int iter = 0; iter < 80; ++iter) {
      Eigen::Matrix<double, 12, 11> jac = Eigen::Matrix<double, 12, 11>::Zero();
      Eigen::Matrix<double, 12, 1> e;
      for (int side = 0; side < 2; ++side) {
        const Chain& c = legs_[static_cast<size_t>(side)];
        std::array<Vec3, 6> p, a;
        Pose t = Pose::Identity();
        for (int i = 0; i < 6; ++i) {
          t.translate(c.origin[i]);
          p[i] = t.translation();
          a[i] = t.linear() * c.axis[i];
          t.rotate(Eigen::AngleAxisd(q[side][i], c.axis[i]));
        }
        pos_err[side] = targets[side]->translation() - t.translation();
        rot_err[side] = rotationError(targets[side]->linear(), t.linear());
        e.segment<3>(6 * side) = pos_err[side];
        const Eigen::Matrix3d to_foot = targets[side]->linear().transpose();
        e.segment<3>(6 * side + 3) = w_axes.asDiagonal() * (to_foot * rot_err[side]);
        for (int i = 0; i < 6; ++i) {
          const int col = i == 0 ? 0 : 1 + 5 * side + (i - 1);
          jac.block<3, 1>(6 * side, col) = a[i].cross(t.translation() - p[i]);
          jac.block<3, 1>(6 * side + 3, col) = w_axes.asDiagonal() * (to_foot * a[i]);
        }
      }
      if (e.norm() < 1e-10) break;
      // Column k's joint: (side, index).
      auto joint = [](int k) {
        return k == 0 ? std::pair{0, 0} : std::pair{(k - 1) / 5, 1 + (k - 1) % 5};
      };
      std::array<bool, 11> active;
      active.fill(true);
      Eigen::VectorXd dq = Eigen::VectorXd::Zero(11);
      for (int pass = 0; pass < 11; ++pass) {
        std::vector<int> cols;
        for (int k = 0; k < 11; ++k)
          if (active[static_cast<size_t>(k)]) cols.push_back(k);
        if (cols.empty()) break;
        Eigen::MatrixXd j(12, static_cast<int>(cols.size()));
        for (size_t k = 0; k < cols.size(); ++k) j.col(static_cast<int>(k)) = jac.col(cols[k]);
        const Eigen::MatrixXd jt = j.transpose();
        const double damping = 1e-9 + 1e-3 * e.squaredNorm();
        const Eigen::VectorXd d =
            (jt * j + damping * Eigen::MatrixXd::Identity(j.cols(), j.cols())).ldlt().solve(jt * e);
        bool changed = false;
        for (size_t k = 0; k < cols.size(); ++k) {
          const auto [side, i] = joint(cols[k]);
          const Chain& c = legs_[static_cast<size_t>(side)];
          const double v = q[static_cast<size_t>(side)][static_cast<size_t>(i)];
          const double step = d[static_cast<int>(k)];
          if ((v <= c.lower[static_cast<size_t>(i)] && step < 0) ||
              (v >= c.upper[static_cast<size_t>(i)] && step > 0)) {
            active[static_cast<size_t>(cols[k])] = false;
            changed = true;
          }
        }
        if (!changed) {
          dq.setZero();
          for (size_t k = 0; k < cols.size(); ++k) dq[cols[k]] = d[static_cast<int>(k)];
          break;
        }
      }
      const double step = dq.norm();
      if (step < 1e-13) break;
      const double scale = step > 0.3 ? 0.3 / step : 1.0;  // no wild jumps far from the goal
      for (int k = 0; k < 11; ++k) {
        const auto [side, i] = joint(k);
        for (int s2 = 0; s2 < 2; ++s2) {
          if (k != 0 && s2 != side) continue;  // the shared hinge moves both legs
          const Chain& c = legs_[static_cast<size_t>(s2)];
          double& v = q[static_cast<size_t>(s2)][static_cast<size_t>(i)];
          v = std::clamp(v + scale * dq[k], c.lower[static_cast<size_t>(i)],
                         c.upper[static_cast<size_t>(i)]);
        }
      }
      q[1][0] = q[0][0];  // one motor (the limits are the same; keep them equal exactly)
    }
    pe = std::max(pos_err[0].norm(), pos_err[1].norm());
    oe = std::max(rot_err[0].norm(), rot_err[1].norm());
    return q;
  };
  const LegAngles bent{0.0, 0.0, -0.45, 0.9, -0.45, 0.0};
  std::array<LegAngles, 2> q0{start ? start->left : bent, start ? start->right : bent};
  q0[1][0] = q0[0][0];
  double pe = 0, oe = 0;
  std::array<LegAngles, 2> best = run(q0, pe, oe);
  double best_cost = pe + w * oe;
  for (double knee : {0.6, 1.4, 0.2, 2.0}) {
    if (best_cost < 1e-8) break;
    const LegAngles k{0.0, 0.0, -0.5 * knee, knee, -0.5 * knee, 0.0};
    double p2 = 0, o2 = 0;
    const auto r = run({k, k}, p2, o2);
    if (p2 + w * o2 < best_cost) {
      best = r;
      best_cost = p2 + w * o2;
      pe = p2;
      oe = o2;
    }
  }
  LegSolution s;
  s.left = best[0];
  s.right = best[1];
  s.position_error = pe;
  s.orientation_error = oe;
  return s;
}

void LegKinematics::writeTargets(const LegSolution& legs, std::vector<double>& targets) const {
  for (int side = 0; side < 2; ++side) {
    const Chain& c = legs_[static_cast<size_t>(side)];
    const LegAngles& q = side == 0 ? legs.left : legs.right;
    for (int i = 0; i < 6; ++i)
      targets[static_cast<size_t>(c.joint[i])] = std::clamp(q[i], c.lower[i], c.upper[i]);
  }
}

}  // namespace simsoccer::agents

#include "simsoccer/agents/motion/leg_kinematics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

namespace simsoccer::agents {

namespace {

// From the last solution, a foot this far from its target (m), or tilted
// this far from it (rad, roll and pitch), means the solve stalled: other
// knee bends are tried.
constexpr double kStalledPosition = 1e-3;
constexpr double kStalledTilt = 1e-2;

// Orientation error as a rotation vector: the rotation taking `current` to `target`.
Vec3 rotationError(const Eigen::Matrix3d& target, const Eigen::Matrix3d& current) {
  const Eigen::AngleAxisd aa(target * current.transpose());
  return aa.angle() * aa.axis();
}

// A joint's part from its axis at zero angles: along y a pitch, along x a roll, else the yaw.
enum class AxisKind { Pitch, Roll, Yaw };
AxisKind axisKind(const Vec3& axis) {
  if (std::abs(axis.y()) > 0.9) return AxisKind::Pitch;
  if (std::abs(axis.x()) > 0.9) return AxisKind::Roll;
  return AxisKind::Yaw;
}

}  // namespace

LegKinematics::LegKinematics(const robots::RobotModel& model) {
  const auto& body = *model.body;
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument("leg kinematics: robot model " + model.name + " (" +
                                model.source_file + "): " + why);
  };
  if (!model.hasLegs()) fail("no `legs` key (each foot's link)");
  for (size_t side = 0; side < 2; ++side) {
    const robots::LegChain& leg = model.legs[side];
    if (leg.joints.size() != 6)
      fail(std::string("legs.") + (side == 0 ? "left" : "right") + ": the leg has " +
           std::to_string(leg.joints.size()) + " joints from the trunk to the foot, not 6");
    Chain& c = legs_[side];
    foot_link_[side] = leg.foot_link;
    for (size_t i = 0; i < 6; ++i) {
      const engine::Joint& joint = body.joints[static_cast<size_t>(leg.joints[i])];
      c.joint[i] = leg.joints[i];
      c.origin[i] = joint.origin;
      c.axis[i] = joint.axis.normalized();
      c.lower[i] = joint.lower;
      c.upper[i] = joint.upper;
    }
  }
  // The parts, from the left leg's axes: pitch joints hip, knee, ankle in
  // that order; roll joints hip, ankle; one yaw; the ankle's pitch and roll last.
  std::vector<int> pitch, roll, yaw;
  for (int i = 0; i < 6; ++i) {
    const AxisKind k = axisKind(legs_[0].axis[static_cast<size_t>(i)]);
    if (axisKind(legs_[1].axis[static_cast<size_t>(i)]) != k)
      fail(
          "legs: " + body.joints[static_cast<size_t>(legs_[0].joint[static_cast<size_t>(i)])].name +
          " and " + body.joints[static_cast<size_t>(legs_[1].joint[static_cast<size_t>(i)])].name +
          " turn about different axes");
    (k == AxisKind::Pitch ? pitch : k == AxisKind::Roll ? roll : yaw).push_back(i);
  }
  if (pitch.size() != 3 || roll.size() != 2 || yaw.size() != 1 || pitch[2] != 4 || roll[1] != 5)
    fail(
        "legs: a leg must have three pitch joints (hip, knee, ankle), two roll joints (hip, "
        "ankle) and a hip yaw, the ankle's pitch and roll last");
  part_ = {yaw[0], roll[0], pitch[0], pitch[1], pitch[2], roll[1]};
  // Joints of the right leg that follow the left one's (one motor).
  for (size_t i = 0; i < 6; ++i) {
    const engine::Joint& right = body.joints[static_cast<size_t>(legs_[1].joint[i])];
    shared_[i] = right.mimic_of == legs_[0].joint[i];
    mimic_[i] = shared_[i] ? right.mimic_multiplier : 0.0;
    if (right.mimic_of >= 0 && !shared_[i])
      fail("the right leg's " + right.name + " mimics a joint other than the left leg's twin");
  }
  // The sole: the lowest point of the foot's collision shapes in its frame.
  for (const engine::Shape& s : body.links[static_cast<size_t>(foot_link_[0])].shapes) {
    double bottom = s.pose.translation().z();
    if (s.type == engine::ShapeType::Box) bottom -= 0.5 * s.extents.z();
    if (s.type == engine::ShapeType::Sphere) bottom -= s.radius;
    sole_depth_ = std::max(sole_depth_, -bottom);
  }
}

std::optional<Eigen::Vector3d> LegKinematics::footAgainst(
    Leg foot, Leg other, const std::vector<double>& body_angles) const {
  constexpr double kFlatHeight = 0.01, kFlatTilt = 0.05;  // m, rad
  const Pose rel =
      forwardFromBody(other, body_angles).inverse() * forwardFromBody(foot, body_angles);
  if (std::abs(rel.translation().z()) > kFlatHeight || rel.linear()(2, 2) < std::cos(kFlatTilt))
    return std::nullopt;
  return Eigen::Vector3d(rel.translation().x(), rel.translation().y(),
                         std::atan2(rel.linear()(1, 0), rel.linear()(0, 0)));
}

Eigen::Vector2d LegKinematics::feetCentre(const std::vector<double>& body_angles, double roll,
                                          double pitch) const {
  const Vec3 middle = 0.5 * (forwardFromBody(Leg::Left, body_angles).translation() +
                             forwardFromBody(Leg::Right, body_angles).translation());
  // Levelled: the torso's attitude is yaw * pitch * roll (the IMU's angles, z-y-x).
  const Vec3 level =
      Eigen::AngleAxisd(pitch, Vec3::UnitY()) * Eigen::AngleAxisd(roll, Vec3::UnitX()) * middle;
  return {level.x(), level.y()};
}

Pose LegKinematics::forwardFromBody(Leg leg, const std::vector<double>& body_angles) const {
  LegAngles q{};
  for (size_t i = 0; i < q.size(); ++i) q[i] = body_angles.at(static_cast<size_t>(joints(leg)[i]));
  return forward(leg, q);
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
  // Both legs at once: one unknown per motor (a Nao: 11, its HipYawPitch
  // shared; a K1: 12) for 12 equations (two foot poses), damped least squares with
  // joints at a limit they push against taken out; restarts from other
  // knee bends if it stalls. Positions weigh more than orientations (0.05 m
  // per rad), so when the feet's yaws disagree the positions are kept.
  // Weights (m per rad) of the orientation error, in the target foot's
  // frame: a foot must land flat (roll, pitch), its yaw may give where the
  // shared hinge cannot serve both feet.
  const double w = 0.05;
  const Eigen::Vector3d w_axes(0.2, 0.2, 0.03);
  const std::array<const Pose*, 2> targets{&left_foot, &right_foot};
  // The unknowns: the left leg's six joints, then the right leg's own (not
  // shared). Sizes are bounded by 12: no allocation per call (an agent
  // solves once per control period).
  std::array<std::array<int, 6>, 2> column{};
  std::array<std::pair<int, int>, 12> unknown{};  // column -> (side, index)
  int n = 0;
  for (int side = 0; side < 2; ++side)
    for (int i = 0; i < 6; ++i) {
      if (side == 1 && shared_[static_cast<size_t>(i)]) {
        column[1][static_cast<size_t>(i)] = column[0][static_cast<size_t>(i)];
        continue;
      }
      column[static_cast<size_t>(side)][static_cast<size_t>(i)] = n;
      unknown[static_cast<size_t>(n++)] = {side, i};
    }
  using Jacobian = Eigen::Matrix<double, 12, Eigen::Dynamic, 0, 12, 12>;
  using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 12>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 12, 1>;
  // How a column's step moves a joint of `side` (the mimic's multiplier on the right).
  const auto gain = [&](int side, int i) {
    return side == 1 && shared_[static_cast<size_t>(i)] ? mimic_[static_cast<size_t>(i)] : 1.0;
  };
  // pe, oe: the larger position (m) and orientation (rad) error of the two
  // feet; tilt: the larger roll and pitch error, in the target foot's frame.
  auto run = [&](std::array<LegAngles, 2> q, double& pe, double& oe, double& tilt) {
    std::array<Vec3, 2> pos_err{}, rot_err{};
    for (int iter = 0; iter < 80; ++iter) {
      Jacobian jac = Jacobian::Zero(12, n);
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
          const int col = column[static_cast<size_t>(side)][static_cast<size_t>(i)];
          const double g = gain(side, i);
          jac.block<3, 1>(6 * side, col) = g * a[i].cross(t.translation() - p[i]);
          jac.block<3, 1>(6 * side + 3, col) = g * (w_axes.asDiagonal() * (to_foot * a[i]));
        }
      }
      if (e.norm() < 1e-10) break;
      std::array<bool, 12> active;
      active.fill(true);
      std::array<double, 12> dq{};
      for (int pass = 0; pass < n; ++pass) {
        std::array<int, 12> cols_at{};
        size_t count = 0;
        for (int k = 0; k < n; ++k)
          if (active[static_cast<size_t>(k)]) cols_at[count++] = k;
        const std::span<const int> cols(cols_at.data(), count);
        if (cols.empty()) break;
        Jacobian j(12, static_cast<int>(cols.size()));
        for (size_t k = 0; k < cols.size(); ++k) j.col(static_cast<int>(k)) = jac.col(cols[k]);
        const double damping = 1e-9 + 1e-3 * e.squaredNorm();
        // Coefficient products: at 12 x 11 a general product's packing costs more.
        Square normal = j.transpose().lazyProduct(j);
        normal.diagonal().array() += damping;
        const Vector d = normal.ldlt().solve(j.transpose().lazyProduct(e));
        bool changed = false;
        for (size_t k = 0; k < cols.size(); ++k) {
          const auto [side, i] = unknown[static_cast<size_t>(cols[k])];
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
          for (size_t k = 0; k < cols.size(); ++k)
            dq[static_cast<size_t>(cols[k])] = d[static_cast<int>(k)];
          break;
        }
      }
      const double step = Eigen::Map<const Eigen::Matrix<double, 12, 1>>(dq.data()).norm();
      // Done when a step moves the joints less than a nanoradian: commands
      // are quantised to 1e-4 rad (a yaw the shared hinge cannot serve keeps
      // a residual, so the error alone would not end the iterations).
      if (step < 1e-9) break;
      const double scale = step > 0.3 ? 0.3 / step : 1.0;  // no wild jumps far from the goal
      for (int side = 0; side < 2; ++side) {
        const Chain& c = legs_[static_cast<size_t>(side)];
        for (size_t i = 0; i < 6; ++i) {
          double& v = q[static_cast<size_t>(side)][i];
          if (side == 1 && shared_[i]) {
            v = mimic_[i] * q[0][i];  // one motor: the mimic follows exactly
            continue;
          }
          v = std::clamp(v + scale * dq[static_cast<size_t>(column[static_cast<size_t>(side)][i])],
                         c.lower[i], c.upper[i]);
        }
      }
    }
    pe = std::max(pos_err[0].norm(), pos_err[1].norm());
    oe = std::max(rot_err[0].norm(), rot_err[1].norm());
    tilt = 0;
    for (int side = 0; side < 2; ++side)
      tilt = std::max(tilt, (targets[side]->linear().transpose() * rot_err[side]).head<2>().norm());
    return q;
  };
  // Starts: the legs bent at the knee by `knee` (rad), the feet flat.
  const auto bent = [&](double knee) {
    LegAngles q{};
    q[static_cast<size_t>(index(LegJoint::HipPitch))] = -0.5 * knee;
    q[static_cast<size_t>(index(LegJoint::Knee))] = knee;
    q[static_cast<size_t>(index(LegJoint::AnklePitch))] = -0.5 * knee;
    return q;
  };
  const auto share = [&](std::array<LegAngles, 2> q) {
    for (size_t i = 0; i < 6; ++i)
      if (shared_[i]) q[1][i] = mimic_[i] * q[0][i];
    return q;
  };
  const std::array<LegAngles, 2> q0 =
      share({start ? start->left : bent(0.9), start ? start->right : bent(0.9)});
  double pe = 0, oe = 0, tilt = 0;
  std::array<LegAngles, 2> best = run(q0, pe, oe, tilt);
  double best_cost = pe + w * oe;
  // With a shared hinge, from the last solution, restarts only when its
  // branch lost a foot's position or flatness (a leg stalled at a limit): a
  // yaw the shared hinge cannot serve is no better from other knee bends (in
  // the Nao's walk they gained under 1e-14 and cost four times the solve).
  const bool shares_a_hinge = std::find(shared_.begin(), shared_.end(), true) != shared_.end();
  const bool stalled =
      start && shares_a_hinge ? pe > kStalledPosition || tilt > kStalledTilt : best_cost >= 1e-8;
  for (double knee : {0.6, 1.4, 0.2, 2.0}) {
    if (!stalled || best_cost < 1e-8) break;
    double p2 = 0, o2 = 0, t2 = 0;
    const auto r = run(share({bent(knee), bent(knee)}), p2, o2, t2);
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

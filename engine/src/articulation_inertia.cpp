#include "articulation_inertia.hpp"

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>
#include <cmath>

namespace simsoccer::engine {
namespace {

Eigen::Vector3d toEigen(const btVector3& v) {
  return {double(v.x()), double(v.y()), double(v.z())};
}
Eigen::Matrix3d toEigen(const btMatrix3x3& m) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = double(m[i][j]);
  return r;
}

}  // namespace

bool ArticulationInertia::supports(const btMultiBody& body) {
  if (body.hasFixedBase() || body.isBaseKinematic()) return false;
  for (int l = 0; l < body.getNumLinks(); ++l) {
    const btMultibodyLink& link = body.getLink(l);
    if (link.m_jointType != btMultibodyLink::eRevolute &&
        link.m_jointType != btMultibodyLink::eFixed)
      return false;
    if (link.m_collider && link.m_collider->isKinematicObject()) return false;
  }
  return true;
}

void ArticulationInertia::setUp(const btMultiBody& body) {
  const int links = body.getNumLinks();
  n_ = 6 + body.getNumDofs();
  const auto n = static_cast<size_t>(n_);
  const auto bodies = static_cast<size_t>(links) + 1;
  parent_.resize(n);
  motion_angular_.resize(n);
  motion_linear_.resize(n);
  coordinate_body_.resize(n);
  composite_.resize(bodies);
  last_coordinate_.resize(bodies);
  matrix_.resize(n * n);  // only entries between a coordinate and its ancestors are used
  inverse_d_.resize(n);
  scratch_.resize(6 * n);
  // The coordinates form a tree: the base's six a chain (turning about the
  // origin, then translating), each joint's parent the nearest coordinate of
  // its parent link or the ones above it.
  for (int a = 0; a < 6; ++a) {
    const auto k = static_cast<size_t>(a);
    parent_[k] = a - 1;
    coordinate_body_[k] = 0;
    const Eigen::Vector3d unit = Eigen::Vector3d::Unit(a % 3);
    motion_angular_[k] = a < 3 ? unit : Eigen::Vector3d::Zero();
    motion_linear_[k] = a < 3 ? Eigen::Vector3d::Zero() : unit;
  }
  last_coordinate_[0] = 5;
  for (int l = 0; l < links; ++l) {
    const btMultibodyLink& link = body.getLink(l);
    const auto self = static_cast<size_t>(l) + 1;
    const auto above = static_cast<size_t>(link.m_parent + 1);
    if (link.m_dofCount == 0) {
      last_coordinate_[self] = last_coordinate_[above];
      continue;
    }
    const auto k = static_cast<size_t>(6 + link.m_dofOffset);
    parent_[k] = last_coordinate_[above];
    coordinate_body_[k] = l + 1;
    last_coordinate_[self] = static_cast<int>(k);
  }
  // L's pattern, by rows over each coordinate's ancestors.
  row_start_.assign(1, 0);
  column_.clear();
  for (size_t k = 0; k < n; ++k) {
    for (int i = parent_[k]; i >= 0; i = parent_[static_cast<size_t>(i)]) column_.push_back(i);
    row_start_.push_back(static_cast<int>(column_.size()));
  }
  entry_.resize(column_.size());
}

bool ArticulationInertia::factor(const btMultiBody& body) {
  columns_ready_ = false;
  const int links = body.getNumLinks();
  const auto n = static_cast<size_t>(n_);

  // Each body alone about the base's centre of mass: mass m, first moment
  // m c, rotational inertia I_c + m (|c|^2 1 - c c^T); and each revolute
  // joint's motion about the origin, turning about its axis through its
  // pivot p: (axis, p x axis).
  const Eigen::Vector3d origin = toEigen(body.getBasePos());
  origin_ = origin;
  {
    const Eigen::Matrix3d rotation = toEigen(btMatrix3x3(body.getWorldToBaseRot().inverse()));
    composite_[0] = {double(body.getBaseMass()), Eigen::Vector3d::Zero(),
                     rotation * toEigen(body.getBaseInertia()).asDiagonal() * rotation.transpose()};
  }
  for (int l = 0; l < links; ++l) {
    const btMultibodyLink& link = body.getLink(l);
    const Eigen::Matrix3d rotation = toEigen(link.m_cachedWorldTransform.getBasis());
    const Eigen::Vector3d c = toEigen(link.m_cachedWorldTransform.getOrigin()) - origin;
    const double m = link.m_mass;
    const Eigen::Matrix3d inertia =
        rotation * toEigen(link.m_inertiaLocal).asDiagonal() * rotation.transpose() +
        m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    composite_[static_cast<size_t>(l) + 1] = {m, m * c, inertia};
    if (link.m_dofCount == 0) continue;
    const auto k = static_cast<size_t>(6 + link.m_dofOffset);
    const Eigen::Vector3d axis = rotation * toEigen(link.getAxisTop(0));
    const Eigen::Vector3d pivot = toEigen(link.m_cachedWorldTransform.getOrigin()) -
                                  rotation * toEigen(link.m_dVector) - origin;
    motion_angular_[k] = axis;
    motion_linear_[k] = pivot.cross(axis);
  }

  // Composite bodies: each link with everything outboard of it (children
  // come after their parents, so one backward sweep adds them up).
  for (int l = links - 1; l >= 0; --l) {
    const Body& child = composite_[static_cast<size_t>(l) + 1];
    Body& parent = composite_[static_cast<size_t>(body.getLink(l).m_parent + 1)];
    parent.mass += child.mass;
    parent.moment += child.moment;
    parent.inertia += child.inertia;
  }

  // M: coordinate k moves its body's composite; the momentum that motion
  // gives it (angular about the origin: I w + h x v; linear: m v + w x h)
  // paired with each coordinate on the way to the root.
  for (size_t k = 0; k < n; ++k) {
    const Body& c = composite_[static_cast<size_t>(coordinate_body_[k])];
    const Eigen::Vector3d& w = motion_angular_[k];
    const Eigen::Vector3d& v = motion_linear_[k];
    const Eigen::Vector3d angular = c.inertia * w + c.moment.cross(v);
    const Eigen::Vector3d linear = c.mass * v + w.cross(c.moment);
    for (int j = static_cast<int>(k); j >= 0; j = parent_[static_cast<size_t>(j)]) {
      const auto jj = static_cast<size_t>(j);
      matrix_[k * n + jj] = motion_angular_[jj].dot(angular) + motion_linear_[jj].dot(linear);
    }
  }

  // M = L^T D L in place, leaves first (Featherstone's LTDL): only entries
  // between a coordinate and its ancestors are touched, so none fill in.
  for (int k = n_ - 1; k >= 0; --k) {
    const double* row_k = &matrix_[static_cast<size_t>(k) * n];
    const double diagonal = row_k[k];
    // A coordinate that moves no inertia (a link whose inertia about the
    // axis is zero: a point mass on its axis): Bullet's pass freezes it; here
    // the factorisation declines. (A massless link is refused by the model check.)
    if (!(diagonal > 1e-12)) return false;
    for (int i = parent_[static_cast<size_t>(k)]; i >= 0; i = parent_[static_cast<size_t>(i)]) {
      const double a = row_k[i] / diagonal;
      double* row_i = &matrix_[static_cast<size_t>(i) * n];
      for (int j = i; j >= 0; j = parent_[static_cast<size_t>(j)]) row_i[j] -= a * row_k[j];
      matrix_[static_cast<size_t>(k) * n + static_cast<size_t>(i)] = a;
    }
  }
  // L's entries in the pattern setUp laid out (row k: k's ancestors).
  for (size_t k = 0; k < n; ++k) {
    inverse_d_[k] = 1.0 / matrix_[k * n + k];
    for (auto e = static_cast<size_t>(row_start_[k]); e < static_cast<size_t>(row_start_[k + 1]);
         ++e)
      entry_[e] = matrix_[k * n + static_cast<size_t>(column_[e])];
  }
  return true;
}

void ArticulationInertia::setColumnCoordinates(std::vector<int> coordinates) {
  column_coordinates_ = std::move(coordinates);
  column_slot_.assign(static_cast<size_t>(n_), -1);
  for (size_t s = 0; s < column_coordinates_.size(); ++s)
    column_slot_.at(static_cast<size_t>(column_coordinates_[s])) = static_cast<int>(s);
  // Whole blocks of six: the last one padded with zero forces.
  const size_t blocks = (column_coordinates_.size() + 5) / 6;
  columns_.assign(blocks * 6 * static_cast<size_t>(n_), btScalar(0));
  columns_ready_ = false;
}

const btScalar* ArticulationInertia::column(int coordinate) const {
  if (coordinate < 0 || coordinate >= n_) return nullptr;
  const int slot = column_slot_.empty() ? -1 : column_slot_[static_cast<size_t>(coordinate)];
  if (slot < 0) return nullptr;
  const auto n = static_cast<size_t>(n_);
  if (!columns_ready_) {
    // Unit forces, six per block solve. A unit force's solve touches rows off
    // its own chain with zeros only, so each column is the same as solve()'s.
    std::vector<btScalar>& forces = unit_forces_;
    for (size_t first = 0; first < column_coordinates_.size(); first += 6) {
      forces.assign(6 * n, btScalar(0));
      for (size_t r = 0; r < 6 && first + r < column_coordinates_.size(); ++r)
        forces[r * n + static_cast<size_t>(column_coordinates_[first + r])] = 1;
      solveBlock<6>(forces.data(), &columns_[first * n], -1);
    }
    columns_ready_ = true;
  }
  return &columns_[static_cast<size_t>(slot) * n];
}

void ArticulationInertia::solve(const btScalar* force, btScalar* response, int chain) const {
  solveBlock<1>(force, response, chain);
}

void ArticulationInertia::solveSix(const btScalar* forces, btScalar* responses, int chain) const {
  solveBlock<6>(forces, responses, chain);
}

// kCount right-hand sides at once, interleaved in the scratch array so that
// each entry of L is loaded once and applied to all of them (a loop the
// compiler vectorises).
template <int kCount>
void ArticulationInertia::solveBlock(const btScalar* force, btScalar* response, int chain) const {
  const auto n = static_cast<size_t>(n_);
  double* x = scratch_.data();
  for (size_t k = 0; k < n; ++k)
    for (size_t r = 0; r < kCount; ++r) x[k * kCount + r] = force[r * n + k];
  // L^T y = f, leaves first (row k of L reaches only k's ancestors, so with
  // the force on one path only that path changes); then D; then L x = y,
  // root first.
  const auto eliminate = [&](size_t k) {
    const double* xk = &x[k * kCount];
    const auto end = static_cast<size_t>(row_start_[k + 1]);
    for (auto e = static_cast<size_t>(row_start_[k]); e < end; ++e) {
      const double l = entry_[e];
      double* xi = &x[static_cast<size_t>(column_[e]) * kCount];
      for (size_t r = 0; r < kCount; ++r) xi[r] -= l * xk[r];
    }
  };
  if (chain >= 0)
    for (int k = chain; k >= 0; k = parent_[static_cast<size_t>(k)])
      eliminate(static_cast<size_t>(k));
  else
    for (size_t k = n; k-- > 0;) eliminate(k);
  for (size_t k = 0; k < n; ++k)
    for (size_t r = 0; r < kCount; ++r) x[k * kCount + r] *= inverse_d_[k];
  for (size_t k = 0; k < n; ++k) {
    double sum[kCount];
    for (size_t r = 0; r < kCount; ++r) sum[r] = x[k * kCount + r];
    const auto end = static_cast<size_t>(row_start_[k + 1]);
    for (auto e = static_cast<size_t>(row_start_[k]); e < end; ++e) {
      const double l = entry_[e];
      const double* xi = &x[static_cast<size_t>(column_[e]) * kCount];
      for (size_t r = 0; r < kCount; ++r) sum[r] -= l * xi[r];
    }
    for (size_t r = 0; r < kCount; ++r) {
      x[k * kCount + r] = sum[r];
      response[r * n + k] = static_cast<btScalar>(sum[r]);
    }
  }
}

void ArticulationInertia::basisJacobians(int link, const btVector3& point, btScalar* rows) const {
  const auto n = static_cast<size_t>(n_);
  std::fill(rows, rows + 6 * n, btScalar(0));
  const Eigen::Vector3d arm = toEigen(point) - origin_;
  for (int j = chainOf(link); j >= 0; j = parent_[static_cast<size_t>(j)]) {
    const auto c = static_cast<size_t>(j);
    const Eigen::Vector3d& w = motion_angular_[c];
    const Eigen::Vector3d v = motion_linear_[c] + w.cross(arm);
    for (size_t a = 0; a < 3; ++a) {
      rows[a * n + c] = static_cast<btScalar>(w[static_cast<Eigen::Index>(a)]);
      rows[(3 + a) * n + c] = static_cast<btScalar>(v[static_cast<Eigen::Index>(a)]);
    }
  }
}

const ArticulationInertia* ArticulationInertias::of(btMultiBody& body) {
  const auto index = static_cast<size_t>(body.getUserIndex());
  if (index >= entries_.size()) return nullptr;
  Entry& e = entries_[index];
  if (e.step == step_) return e.factored ? &e.inertia : nullptr;
  e.step = step_;
  if (!e.set_up) {  // the model's structure: once
    e.set_up = true;
    e.supported = ArticulationInertia::supports(body);
    if (e.supported) {
      e.inertia.setUp(body);
      e.inertia.setColumnCoordinates(e.column_coordinates);
    }
  }
  e.factored = e.supported && e.inertia.factor(body);
  if (!e.factored) return nullptr;
  if (check_) e.mismatch = std::max(e.mismatch, checkAgainstBullet(body, e.inertia));
  return &e.inertia;
}

namespace {

// The largest difference between two vectors of n entries relative to the
// second's largest entry.
double relativeDifference(const btScalar* mine, const btScalar* theirs, size_t n) {
  double scale = 0, difference = 0;
  for (size_t k = 0; k < n; ++k) {
    scale = std::max(scale, std::abs(double(theirs[k])));
    difference = std::max(difference, std::abs(double(mine[k]) - double(theirs[k])));
  }
  return scale > 0 ? difference / scale : difference;
}

}  // namespace

double ArticulationInertias::checkAgainstBullet(btMultiBody& body,
                                                const ArticulationInertia& inertia) {
  const auto n = static_cast<size_t>(inertia.size());
  std::vector<btScalar> unit(n, 0), ours(n), bullets(n);
  btAlignedObjectArray<btScalar> scratch_r;
  btAlignedObjectArray<btVector3> scratch_v;
  btAlignedObjectArray<btMatrix3x3> scratch_m;
  double worst = 0;
  // M^-1, column by column; and the columns the servo rows take, solved six at a time.
  for (size_t i = 0; i < n; ++i) {
    unit[i] = 1;
    inertia.solve(unit.data(), ours.data());
    body.calcAccelerationDeltasMultiDof(unit.data(), bullets.data(), scratch_r, scratch_v);
    unit[i] = 0;
    worst = std::max(worst, relativeDifference(ours.data(), bullets.data(), n));
    if (const btScalar* column = inertia.column(static_cast<int>(i)))
      worst = std::max(worst, relativeDifference(column, bullets.data(), n));
  }
  // Each link's basis rows and their responses as the solver gets them (the
  // six at once, along the link's path only).
  std::vector<btScalar> rows(6 * n), responses(6 * n);
  for (int link = -1; link < body.getNumLinks(); ++link) {
    const btVector3 point =
        link < 0 ? body.getBasePos() : body.getLink(link).m_cachedWorldTransform.getOrigin();
    inertia.basisJacobians(link, point, rows.data());
    inertia.solveSix(rows.data(), responses.data(), inertia.chainOf(link));
    for (size_t a = 0; a < 6; ++a) {
      btVector3 angular(0, 0, 0), linear(0, 0, 0);
      (a < 3 ? angular : linear)[static_cast<int>(a % 3)] = 1;
      body.fillConstraintJacobianMultiDof(link, point, angular, linear, bullets.data(), scratch_r,
                                          scratch_v, scratch_m);
      body.calcAccelerationDeltasMultiDof(bullets.data(), ours.data(), scratch_r, scratch_v);
      worst = std::max({worst, relativeDifference(&rows[a * n], bullets.data(), n),
                        relativeDifference(&responses[a * n], ours.data(), n)});
    }
  }
  return worst;
}

double ArticulationInertias::mismatch() const {
  double worst = -1;
  for (const Entry& e : entries_) worst = std::max(worst, e.mismatch);
  return worst;
}

}  // namespace simsoccer::engine

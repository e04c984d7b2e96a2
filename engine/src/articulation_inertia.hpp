// The joint-space inertia matrix of one articulation, factorised along its
// tree (engine-internal).
//
// Every row the solver builds for an articulation needs its response
// M^-1 J^T. Bullet computes it with one articulated-body pass per row
// (btMultiBody::calcAccelerationDeltasMultiDof: O(links), a large constant):
// a fifth of a 22-robot step. Here M is built once per step and articulation
// by the composite-rigid-body algorithm and factorised as M = L^T D L
// (Featherstone, "Efficient factorization of the joint-space inertia matrix
// for branched kinematic trees", IJRR 2005: no fill-in, work O(coordinates x
// depth)); a response is then two sparse triangular solves. Same quantity,
// different rounding: this is computed in double precision from Bullet's
// single-precision state.
//
// Coordinates are Bullet's generalised velocities: the base's angular and
// linear velocity (its centre of mass) in the world frame, then the joint
// rates in link order. Spatial quantities are taken about the base's centre
// of mass, so that positions stay small (no cancellation on a big field).
#pragma once

#include <LinearMath/btScalar.h>
#include <LinearMath/btVector3.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

class btMultiBody;

namespace simsoccer::engine {

class ArticulationInertia {
 public:
  // A floating base and revolute or fixed joints (the robot models); any
  // other articulation keeps Bullet's pass.
  static bool supports(const btMultiBody& body);

  // The tree's structure, which the model fixes: the coordinates' parents,
  // L's pattern, the arrays' sizes. Once per articulation, before factor().
  void setUp(const btMultiBody& body);

  // Builds and factorises M at the body's configuration: its base pose and
  // its links' cached world transforms (as forward kinematics left them).
  // False where a coordinate moves no inertia (then Bullet's pass is used).
  bool factor(const btMultiBody& body);

  // response = M^-1 force, 6 + dofs entries each. `chain`: a coordinate such
  // that force is zero off the path from it to the root (a row on a link:
  // chainOf(link); a joint row: its coordinate), which halves the work; -1:
  // any force. Uses a scratch array of this object: one thread at a time (an
  // articulation's rows are built by the thread of its batch).
  void solve(const btScalar* force, btScalar* response, int chain = -1) const;
  // Six at once (a link's basis), each of size() entries one after the other.
  void solveSix(const btScalar* forces, btScalar* responses, int chain = -1) const;
  // The coordinates whose joint rows (implicit servos) will ask for their
  // response each step: column() solves all of them together.
  void setColumnCoordinates(std::vector<int> coordinates);
  // The response to a unit force at `coordinate` (column `coordinate` of
  // M^-1, size() entries), the same numbers as solve() of that unit force:
  // on the first call after factor() every registered coordinate's, six
  // right-hand sides per block solve. Null for a coordinate not registered.
  const btScalar* column(int coordinate) const;
  // The last coordinate on the path from a link (-1: the base) to the root.
  int chainOf(int link) const { return last_coordinate_[static_cast<size_t>(link + 1)]; }

  // The six rows of a link's spatial basis at a world point fixed to it
  // (angular x, y, z, then the point's linear x, y, z: the rows
  // btMultiBody::fillConstraintJacobianMultiDof fills, from the motion
  // subspaces along the link's path instead of a pass over all links):
  // 6 x size() entries.
  void basisJacobians(int link, const btVector3& point, btScalar* rows) const;

  int size() const { return n_; }

 private:
  template <int kCount>
  void solveBlock(const btScalar* force, btScalar* response, int chain) const;

  struct Body {  // mass, first moment and rotational inertia about the base's centre of mass
    double mass;
    Eigen::Vector3d moment;
    Eigen::Matrix3d inertia;
  };
  int n_ = 0;
  Eigen::Vector3d origin_;      // the base's centre of mass, world
  std::vector<int> parent_;     // per coordinate: the next one toward the root, -1 at the root
  std::vector<double> matrix_;  // n x n, lower triangle: M, then L (D on the diagonal)
  std::vector<double> inverse_d_;
  // L by rows over each coordinate's ancestors (their column, their entry),
  // contiguous for the solves.
  std::vector<int> row_start_, column_;
  std::vector<double> entry_;
  std::vector<Body> composite_;                                  // per body (0: the base, 1 + link)
  std::vector<Eigen::Vector3d> motion_angular_, motion_linear_;  // per coordinate
  std::vector<int> coordinate_body_;                             // per coordinate
  std::vector<int> last_coordinate_;  // per body: its own last coordinate or the nearest above
  mutable std::vector<double> scratch_;
  std::vector<int> column_coordinates_;  // registered, in order
  std::vector<int> column_slot_;         // per coordinate: its slot in columns_, or -1
  mutable std::vector<btScalar> columns_;
  mutable std::vector<btScalar> unit_forces_;
  mutable bool columns_ready_ = false;
};

// The factorisations of a world's articulations (by their user index), one
// per step, each made on first use by the thread that solves the
// articulation's batch: an articulation is in one batch per step, so no two
// threads touch one entry.
class ArticulationInertias {
 public:
  void resize(size_t articulations) { entries_.resize(articulations); }
  // The joint coordinates of articulation `index` with a row each step that
  // asks for its column (ArticulationInertia::column).
  void setColumnCoordinates(size_t index, std::vector<int> coordinates) {
    entries_.at(index).column_coordinates = std::move(coordinates);
  }
  // Call before a step's rows are built, after its forward kinematics.
  void newStep() { ++step_; }
  // The body's factorisation this step; null where it is not supported.
  const ArticulationInertia* of(btMultiBody& body);

  // Checking (tests): each factorisation's M^-1 against Bullet's
  // articulated-body pass, column by column, and each link's basis rows and
  // their responses (as the solver solves them) against Bullet's Jacobians
  // and passes; the largest difference relative to its column's (row's)
  // largest entry, over all factorisations since turned on (negative: none
  // checked).
  void check(bool on) { check_ = on; }
  double mismatch() const;

 private:
  struct Entry {
    ArticulationInertia inertia;
    uint64_t step = 0;
    bool set_up = false, supported = false;
    bool factored = false;  // this step
    double mismatch = -1;
    std::vector<int> column_coordinates;
  };
  // The largest relative difference of one factorisation against Bullet.
  static double checkAgainstBullet(btMultiBody& body, const ArticulationInertia& inertia);
  std::vector<Entry> entries_;
  uint64_t step_ = 1;
  bool check_ = false;
};

}  // namespace simsoccer::engine

// The engine's multibody constraint solver: Bullet's, with its own contact
// rows for robot links and a leaner iteration loop (engine-internal).
//
// Rows. Bullet builds every contact row of an articulation with one
// articulated-body pass (btMultiBody::calcAccelerationDeltasMultiDof,
// O(links)) for its response and one for its Jacobian. Here the rows of a
// manifold between one or two articulation links and/or something static
// (a foot on the carpet, robot against robot) are built from each link's
// spatial basis: a row along direction d at point p of a link is the
// combination (d, (p - o) x d) of the six rows of the basis at the link's
// origin o (three angular, three linear). The basis's Jacobians come from the
// articulation's factorised inertia (articulation_inertia.hpp); with three or
// more points (a foot flat on the carpet: four points, twelve rows) the
// basis's six responses are solved once and every row's response is their
// combination, below that each row's response is solved on its own. Without
// the factorisation (an articulation it does not support), only a link on
// static ground at three or more points takes this path, its basis from
// Bullet's passes. The rows are otherwise the ones Bullet 3.24 builds (same
// fields, order, friction directions, Baumgarte terms, no warm start without
// SOLVER_USE_ARTICULATED_WARMSTARTING). Rigid bodies (the ball), rolling or
// anisotropic friction and per-contact stiffness go through Bullet's own
// conversion.
//
// Iterations. Bullet's row update adds each impulse's velocity change twice,
// to the solver's delta velocities and to the articulation's pending ones,
// in scalar loops; here each row updates the delta velocities only (in loops
// the compiler vectorises), a joint row (one coordinate per side) reads its
// velocity from that coordinate, and each articulation's total is added once
// after the last iteration. Same rows, order, bounds and friction cone.
//
// Both differ from Bullet's in the last bits only (tests hold pairs of
// robots within micrometres of Bullet's own after a second); `own` false
// leaves everything to Bullet, for comparisons.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>

#include <vector>

namespace simsoccer::engine {

class ArticulationInertia;
class ArticulationInertias;

// The articulation's block of velocity changes in the solver's data (its
// companion id), made at its first row of the group.
int deltaVelocityBlock(btMultiBody* body, btMultiBodyJacobianData& data);

class ArticulationSolver : public btMultiBodyConstraintSolver {
 public:
  explicit ArticulationSolver(bool own) : own_(own) {}

  // Contact rows the engine built since the last reset (for tests and
  // reports): with their responses from a link's basis, solved one by one,
  // and between two articulations.
  long basisRows() const { return basis_rows_; }
  long solvedRows() const { return solved_rows_; }
  long twoArticulationRows() const { return two_articulation_rows_; }
  void resetRowCounts() { basis_rows_ = solved_rows_ = two_articulation_rows_ = 0; }
  // Responses from these factorised inertias where they support the body
  // (null: Bullet's articulated-body pass for every row).
  void setInertias(ArticulationInertias* inertias) { inertias_ = inertias; }
  // Contact rows start from this share of their point's impulses of the last
  // step (normal and both friction directions; 0: from zero, as Bullet's).
  void setWarmStart(btScalar share) { warm_start_ = share; }

 protected:
  void convertContacts(btPersistentManifold** manifolds, int num_manifolds,
                       const btContactSolverInfo& info) override;
  // The articulations' rows as Bullet iterates them (same order, limits and
  // friction cone), each row updating the group's delta velocities only; the
  // articulations' own velocity changes are added once after the last
  // iteration instead of after every row (Bullet does both at every row).
  btScalar solveSingleIteration(int iteration, btCollisionObject** bodies, int num_bodies,
                                btPersistentManifold** manifolds, int num_manifolds,
                                btTypedConstraint** constraints, int num_constraints,
                                const btContactSolverInfo& info, btIDebugDraw* debug_draw) override;
  btScalar solveGroupCacheFriendlyIterations(btCollisionObject** bodies, int num_bodies,
                                             btPersistentManifold** manifolds, int num_manifolds,
                                             btTypedConstraint** constraints, int num_constraints,
                                             const btContactSolverInfo& info,
                                             btIDebugDraw* debug_draw) override;

 private:
  bool lean(const btContactSolverInfo& info) const {
    return own_ && !(info.m_solverMode & SOLVER_USE_ARTICULATED_WARMSTARTING);
  }
  // One projected Gauss-Seidel update of a row; returns its velocity change.
  btScalar resolveRow(btMultiBodySolverConstraint& row);
  // The row's clamped impulse change given the velocity it sees (its applied
  // impulse updated).
  btScalar clampedUpdate(btMultiBodySolverConstraint& row, btScalar velocity);
  // The same for the articulations' own constraint `index`, a joint row
  // (its Jacobian one coordinate per side) in O(1) plus its responses.
  btScalar resolveNonContactRow(int index);
  // Fills joint_rows_ for this group's own constraints.
  void findJointRows();
  // Two friction rows of one contact, clamped together to the friction cone.
  btScalar resolveFrictionPair(btMultiBodySolverConstraint& a, btMultiBodySolverConstraint& b);
  // The row's impulse change applied to the group's velocity changes.
  void applyImpulse(const btMultiBodySolverConstraint& row, btScalar impulse);
  // The velocity change a row sees (both sides).
  btScalar rowVelocity(const btMultiBodySolverConstraint& row);

  // Bullet limits rolling friction about two fixed axes of the contact plane, each on its own:
  // a ball rolling at an angle to them is slowed along both, its path bends towards the nearer
  // axis and it stops short (2 m/s with 0.3 sideways ran straight along the x axis after 0.75 s).
  // The two rolling rows of each contact Bullet builds (a rigid body, the ball, on the carpet,
  // a goal or another rigid body; not on a robot's link) turn to the relative rolling axis and
  // across it, so the resistance opposes the rolling whichever way it goes (its limit, per row,
  // unchanged). Bodies with anisotropic rolling friction keep Bullet's axes.
  void alignRollingFriction();
  // Whether the engine builds the manifold's rows (returns its points within
  // the processing threshold; 0: Bullet builds them). It does for one or two
  // articulation links (factorised) against each other or something static,
  // and without the factorisation for a link on static ground at three or
  // more points; a rigid body, anisotropic, rolling or spinning friction or
  // per-contact settings go through Bullet. Fills sides_.
  int ownContact(const btPersistentManifold& manifold);
  void convertOwnContact(btPersistentManifold& manifold, int points,
                         const btContactSolverInfo& info);
  // One row (normal or friction) along `direction` (world, Bullet's contact
  // normal: from side B to side A) at the contact point.
  void addRow(btMultiBodySolverConstraint& row, btManifoldPoint& point, const btVector3& direction,
              bool friction, const btContactSolverInfo& info);

  // One side of a manifold the engine converts.
  struct ContactSide {
    btMultiBody* body = nullptr;  // null: a static object
    int link = -1;
    int solver_body = -1;  // the static object's solver body
    // The link's origin (Bullet's lever arms start there) or the static body's.
    btVector3 origin;
    const ArticulationInertia* inertia = nullptr;  // null: Bullet's passes for the basis
    bool basis = false;  // responses as combinations of the basis's (three points or more)
    int ndof = 0;
    // The link's basis: 6 Jacobians and (with `basis`) 6 responses, ndof each
    // (angular x, y, z, then linear x, y, z at the link's origin).
    btAlignedObjectArray<btScalar> jacobian, response;
  };

  bool own_;
  btScalar warm_start_ = 0;
  ArticulationInertias* inertias_ = nullptr;
  long basis_rows_ = 0;
  long solved_rows_ = 0;
  long two_articulation_rows_ = 0;
  ContactSide sides_[2];
  // Per own constraint row of the group: whether each side's Jacobian is a
  // single coordinate (servos, gears, limits), which, its value, and whether
  // side B's response is not zero (a servo's is: its parent side is empty).
  struct JointRow {
    bool sparse = false;
    int coordinate_a = 0, coordinate_b = 0;
    btScalar value_a = 0, value_b = 0;
    bool response_b = false;
    btScalar envelope_slope = 0, upper = 0, lower = 0, inv_mass = 0;
  };
  std::vector<JointRow> joint_rows_;
  std::vector<char> applied_;  // per delta-velocity block: added to its articulation
};

}  // namespace simsoccer::engine

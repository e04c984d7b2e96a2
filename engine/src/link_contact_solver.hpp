// Bullet's multibody constraint solver with cheaper rows for a robot link
// resting on something static (engine-internal).
//
// Bullet builds every contact row of an articulation with one articulated-
// body pass (btMultiBody::calcAccelerationDeltasMultiDof, O(links)) for its
// response and one for its Jacobian: a foot flat on the carpet has four
// points of three rows each (the normal and two friction directions), twelve
// passes of each kind, the largest cost of a step with 22 robots. The
// response to a row is linear in the row: a row along direction d at point p
// of a link is the combination (d, (p - o) x d) of the six rows of the link's
// spatial basis at its origin o (three linear, three angular). So for a
// manifold of three or more points between one articulation link and a
// static object, this solver computes the basis's six Jacobians and
// responses once and every row of the manifold as its combination. The rows
// are otherwise the ones Bullet 3.24 builds (same fields, order, friction
// directions, Baumgarte terms, no warm start without
// SOLVER_USE_ARTICULATED_WARMSTARTING); they differ from Bullet's in the last
// bits only. Everything else (rigid bodies, robot against robot, other
// solver modes, rolling friction, anisotropic friction, per-contact
// stiffness) goes through Bullet's own conversion.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>

namespace simsoccer::engine {

class LinkContactSolver : public btMultiBodyConstraintSolver {
 public:
  // basis: false builds every row with Bullet's own conversion (for
  // comparisons).
  explicit LinkContactSolver(bool basis) : basis_(basis) {}

  // Rows built from a link basis since the last reset (for tests and reports).
  long basisRows() const { return basis_rows_; }
  void resetBasisRows() { basis_rows_ = 0; }

 protected:
  void convertContacts(btPersistentManifold** manifolds, int num_manifolds,
                       const btContactSolverInfo& info) override;

 private:
  // Whether the manifold takes the basis path; `link_side` 0: body 0 is the
  // articulation link, 1: body 1 is.
  bool takesBasisPath(const btPersistentManifold& manifold, int& link_side) const;
  void convertLinkContact(btPersistentManifold& manifold, int link_side,
                          const btContactSolverInfo& info);
  // One row (normal or friction) along `direction` (world, from the static
  // side to the link as Bullet's contact normal) at the contact point.
  void addRow(btMultiBodySolverConstraint& row, btManifoldPoint& point, const btVector3& direction,
              bool friction, int link_side, int static_body, const btContactSolverInfo& info);

  bool basis_;
  long basis_rows_ = 0;
  // The link's basis this manifold: 6 Jacobians and 6 responses, ndof each
  // (angular x, y, z, then linear x, y, z at the link's origin).
  btAlignedObjectArray<btScalar> basis_jacobian_, basis_response_;
  btVector3 basis_origin_;
  btMultiBody* body_ = nullptr;  // the manifold's articulation and link
  int link_ = 0;
  int ndof_ = 0;
};

}  // namespace simsoccer::engine

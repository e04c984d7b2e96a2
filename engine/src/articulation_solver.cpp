#include "articulation_solver.hpp"

#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <utility>

#include "articulation_inertia.hpp"

namespace simsoccer::engine {
namespace {

// The basis costs six passes; a point's rows one each (three with two
// friction directions, two with one): from three points on it pays with two
// directions, and costs the same as the rows with one.
constexpr int kMinPoints = 3;
// Per-point settings Bullet honours that the basis path does not implement.
constexpr int kOwnSettings = BT_CONTACT_FLAG_HAS_CONTACT_CFM | BT_CONTACT_FLAG_HAS_CONTACT_ERP |
                             BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING |
                             BT_CONTACT_FLAG_FRICTION_ANCHOR;
constexpr int kAnisotropic =
    btCollisionObject::CF_ANISOTROPIC_FRICTION | btCollisionObject::CF_ANISOTROPIC_ROLLING_FRICTION;

// a . b over n entries in four interleaved partial sums (a fixed order, so
// the result is the same on every run; the compiler can vectorise it).
btScalar dot(const btScalar* a, const btScalar* b, int n) {
  btScalar s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += a[i] * b[i];
    s1 += a[i + 1] * b[i + 1];
    s2 += a[i + 2] * b[i + 2];
    s3 += a[i + 3] * b[i + 3];
  }
  for (; i < n; ++i) s0 += a[i] * b[i];
  return (s0 + s1) + (s2 + s3);
}

// out = sum over k of weight[k] times the basis's row k (ndof entries each):
// basis row by basis row over contiguous arrays (the compiler vectorises
// these), the same sums in the same order for every entry.
void combineBasis(const btScalar weight[6], const btScalar* basis, int ndof, btScalar* out) {
  for (int i = 0; i < ndof; ++i) out[i] = weight[0] * basis[i];
  for (int k = 1; k < 6; ++k) {
    const btScalar* row = &basis[k * ndof];
    for (int i = 0; i < ndof; ++i) out[i] += weight[k] * row[i];
  }
}

void touched(const btMultiBodySolverConstraint& row) {
  if (row.m_multiBodyA) row.m_multiBodyA->setPosUpdated(false);
  if (row.m_multiBodyB) row.m_multiBodyB->setPosUpdated(false);
}

// Gauss-Seidel: the impulse that removes the row's velocity error, softened by its cfm.
btScalar unclampedDelta(const btMultiBodySolverConstraint& row, btScalar velocity) {
  return row.m_rhs - btScalar(row.m_appliedImpulse) * row.m_cfm - velocity * row.m_jacDiagABInv;
}

}  // namespace

int deltaVelocityBlock(btMultiBody* body, btMultiBodyJacobianData& data) {
  int block = body->getCompanionId();
  if (block < 0) {
    block = data.m_deltaVelocities.size();
    body->setCompanionId(block);
    data.m_deltaVelocities.resize(block + body->getNumDofs() + 6);
  }
  return block;
}

void ArticulationSolver::convertContacts(btPersistentManifold** manifolds, int num_manifolds,
                                         const btContactSolverInfo& info) {
  if (!own_ || (info.m_solverMode &
                (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING | SOLVER_USE_ARTICULATED_WARMSTARTING))) {
    btMultiBodyConstraintSolver::convertContacts(manifolds, num_manifolds, info);
    alignRollingFriction();
    return;
  }
  // Manifold by manifold in Bullet's order, so the rows come in its order.
  for (int i = 0; i < num_manifolds; ++i) {
    btPersistentManifold* manifold = manifolds[i];
    if (const int points = ownContact(*manifold))
      convertOwnContact(*manifold, points, info);
    else if (btMultiBodyLinkCollider::upcast(manifold->getBody0()) ||
             btMultiBodyLinkCollider::upcast(manifold->getBody1()))
      convertMultiBodyContact(manifold, info);
    else
      convertContact(manifold, info);
  }
  // Warm start: the contact rows' starting impulses (a share of the last
  // step's) applied before the iterations, as the iterations would apply them.
  if (warm_start_ > 0)
    for (btMultiBodyConstraintArray* rows :
         {&m_multiBodyNormalContactConstraints, &m_multiBodyFrictionContactConstraints})
      for (int j = 0; j < rows->size(); ++j) {
        btMultiBodySolverConstraint& row = (*rows)[j];
        if (row.m_appliedImpulse != 0) applyImpulse(row, btScalar(row.m_appliedImpulse));
      }
  // The articulations' own constraints (limits, servos, gears); without
  // articulated warm starting their rows start from zero impulse.
  for (int i = 0; i < m_tmpNumMultiBodyConstraints; ++i) {
    m_data.m_solverBodyPool = &m_tmpSolverBodyPool;
    m_data.m_fixedBodyId = m_fixedBodyId;
    m_tmpMultiBodyConstraints[i]->createConstraintRows(m_multiBodyNonContactConstraints, m_data,
                                                       info);
  }
  for (int i = 0; i < m_multiBodyNonContactConstraints.size(); ++i)
    m_multiBodyNonContactConstraints[i].m_appliedImpulse = 0;
  alignRollingFriction();
}

void ArticulationSolver::alignRollingFriction() {
  btConstraintArray& rows = m_tmpSolverContactRollingFrictionConstraintPool;
  for (int i = 0; i + 1 < rows.size(); ++i) {
    btSolverConstraint& a = rows[i];
    btSolverConstraint& b = rows[i + 1];
    if (a.m_frictionIndex != b.m_frictionIndex) continue;
    const auto* point = static_cast<const btManifoldPoint*>(
        m_tmpSolverContactConstraintPool[a.m_frictionIndex].m_originalContactPoint);
    if (!point) continue;
    const btSolverBody& body_a = m_tmpSolverBodyPool[a.m_solverBodyIdA];
    const btSolverBody& body_b = m_tmpSolverBodyPool[a.m_solverBodyIdB];
    const auto anisotropic = [](const btSolverBody& body) {
      return body.m_originalBody && body.m_originalBody->hasAnisotropicFriction(
                                        btCollisionObject::CF_ANISOTROPIC_ROLLING_FRICTION);
    };
    if (anisotropic(body_a) || anisotropic(body_b)) continue;
    const btVector3& normal = point->m_normalWorldOnB;
    // A rolling row's axis is its torque axis (the spinning row's is the normal).
    const auto rolling = [&](const btSolverConstraint& row) {
      return btFabs(row.m_relpos2CrossNormal.dot(normal)) < btScalar(0.5);
    };
    if (!rolling(a) || !rolling(b)) continue;
    const btVector3 spin = body_a.m_angularVelocity - body_b.m_angularVelocity;
    btVector3 along = spin - normal * spin.dot(normal);
    if (along.length2() < btScalar(1e-12)) continue;
    along.normalize();
    const btVector3 across = normal.cross(along);
    btManifoldPoint& cp = *const_cast<btManifoldPoint*>(point);
    const btVector3 none(0, 0, 0);
    for (auto [row, axis] : {std::pair{&a, along}, std::pair{&b, across}})
      setupTorsionalFrictionConstraint(*row, axis, row->m_solverBodyIdA, row->m_solverBodyIdB, cp,
                                       row->m_friction, none, none, nullptr, nullptr, 1);
    ++i;  // the pair is done
  }
}

int ArticulationSolver::ownContact(const btPersistentManifold& manifold) {
  const btCollisionObject* object[2] = {manifold.getBody0(), manifold.getBody1()};
  if (object[0]->hasAnisotropicFriction(kAnisotropic) ||
      object[1]->hasAnisotropicFriction(kAnisotropic))
    return 0;
  int links = 0;
  bool factorised = true;
  for (int s = 0; s < 2; ++s) {
    ContactSide& side = sides_[s];
    const btMultiBodyLinkCollider* collider = btMultiBodyLinkCollider::upcast(object[s]);
    if (collider) {
      side.body = collider->m_multiBody;
      side.link = collider->m_link;
      side.inertia = inertias_ ? inertias_->of(*side.body) : nullptr;
      factorised = factorised && side.inertia;
      ++links;
    } else {
      // A static (or kinematic) object: the carpet, a goal; it moves nothing
      // and takes no velocity, as in Bullet's rows. A rigid body (the ball)
      // goes through Bullet.
      if (btRigidBody::upcast(object[s]) != nullptr || !object[s]->isStaticOrKinematicObject())
        return 0;
      side.body = nullptr;
      side.inertia = nullptr;
    }
  }
  if (links == 0) return 0;
  int points = 0;
  for (int j = 0; j < manifold.getNumContacts(); ++j) {
    const btManifoldPoint& p = manifold.getContactPoint(j);
    if (p.m_combinedRollingFriction > 0 || p.m_combinedSpinningFriction > 0 ||
        (p.m_contactPointFlags & kOwnSettings))
      return 0;
    if (p.getDistance() <= manifold.getContactProcessingThreshold()) ++points;
  }
  // Without the factorisation only a link on static ground at three or more
  // points pays (its basis from Bullet's passes).
  if (!factorised && (links == 2 || points < kMinPoints)) return 0;
  return points;
}

void ArticulationSolver::convertOwnContact(btPersistentManifold& manifold, int points,
                                           const btContactSolverInfo& info) {
  btCollisionObject* object[2] = {const_cast<btCollisionObject*>(manifold.getBody0()),
                                  const_cast<btCollisionObject*>(manifold.getBody1())};
  for (int s = 0; s < 2; ++s) {
    ContactSide& side = sides_[s];
    if (!side.body) {
      side.solver_body = getOrInitSolverBody(*object[s], info.m_timeStep);
      side.origin = m_tmpSolverBodyPool[side.solver_body].getWorldTransform().getOrigin();
      continue;
    }
    // The link's spatial basis at its origin (the frame Bullet measures the
    // contact's lever arm from): six Jacobians, and from three points on
    // their six responses, every row's being their combination; below
    // three points each row is solved on its own.
    side.solver_body = -1;
    side.ndof = side.body->getNumDofs() + 6;
    side.origin = side.link < 0 ? side.body->getBasePos()
                                : side.body->getLink(side.link).m_cachedWorldTransform.getOrigin();
    side.basis = points >= kMinPoints;
    side.jacobian.resize(6 * side.ndof);
    side.response.resize(6 * side.ndof);
    if (side.inertia) {
      side.inertia->basisJacobians(side.link, side.origin, &side.jacobian[0]);
      if (side.basis)
        side.inertia->solveSix(&side.jacobian[0], &side.response[0],
                               side.inertia->chainOf(side.link));
    } else {
      for (int k = 0; k < 6; ++k) {
        btVector3 angular(0, 0, 0), linear(0, 0, 0);
        (k < 3 ? angular : linear)[k % 3] = 1;
        btScalar* jacobian = &side.jacobian[k * side.ndof];
        side.body->fillConstraintJacobianMultiDof(side.link, side.origin, angular, linear, jacobian,
                                                  m_data.scratch_r, m_data.scratch_v,
                                                  m_data.scratch_m);
        side.body->calcAccelerationDeltasMultiDof(jacobian, &side.response[k * side.ndof],
                                                  m_data.scratch_r, m_data.scratch_v);
      }
    }
  }

  const bool two_directions = info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS;
  for (int j = 0; j < manifold.getNumContacts(); ++j) {
    btManifoldPoint& point = manifold.getContactPoint(j);
    if (point.getDistance() > manifold.getContactProcessingThreshold()) {
      point.m_appliedImpulse = 0;  // no row: nothing to start the next step from
      point.m_prevRHS = 0;
      continue;
    }
    const int normal_index = m_multiBodyNormalContactConstraints.size();
    btMultiBodySolverConstraint& normal =
        m_multiBodyNormalContactConstraints.expandNonInitializing();
    addRow(normal, point, point.m_normalWorldOnB, /*friction=*/false, info);
    normal.m_appliedImpulse = warm_start_ * point.m_appliedImpulse;
    normal.m_frictionIndex = m_multiBodyFrictionContactConstraints.size();
    // Friction along two fixed tangents of the normal, as Bullet's multibody
    // contacts; the solver clamps the pair to the friction cone.
    btPlaneSpace1(point.m_normalWorldOnB, point.m_lateralFrictionDir1, point.m_lateralFrictionDir2);
    point.m_lateralFrictionDir1.normalize();
    point.m_lateralFrictionDir2.normalize();
    for (int d = 0; d < (two_directions ? 2 : 1); ++d) {
      btMultiBodySolverConstraint& row =
          m_multiBodyFrictionContactConstraints.expandNonInitializing();
      addRow(row, point, d == 0 ? point.m_lateralFrictionDir1 : point.m_lateralFrictionDir2,
             /*friction=*/true, info);
      row.m_appliedImpulse =
          warm_start_ * (d == 0 ? point.m_appliedImpulseLateral1 : point.m_appliedImpulseLateral2);
      row.m_frictionIndex = normal_index;
    }
    if (two_directions &&
        (info.m_solverMode & SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION))
      point.m_contactPointFlags |= BT_CONTACT_FLAG_LATERAL_FRICTION_INITIALIZED;
  }
}

void ArticulationSolver::addRow(btMultiBodySolverConstraint& row, btManifoldPoint& point,
                                const btVector3& direction, bool friction,
                                const btContactSolverInfo& info) {
  row.m_orgConstraint = nullptr;
  row.m_orgDofIndex = -1;
  row.m_originalContactPoint = &point;
  row.m_overrideNumSolverIterations = -1;
  row.m_solverBodyIdA = sides_[0].solver_body;
  row.m_solverBodyIdB = sides_[1].solver_body;
  row.m_multiBodyA = sides_[0].body;
  row.m_multiBodyB = sides_[1].body;
  row.m_linkA = sides_[0].body ? sides_[0].link : -1;
  row.m_linkB = sides_[1].body ? sides_[1].link : -1;

  // Each articulation's row: along +direction at its point on side A, along
  // -direction on side B; the basis combination (lever arm x direction,
  // direction) gives its Jacobian and, with the basis's responses, its
  // response. Effective mass (J M^-1 J^T, both sides) and velocity.
  const btVector3 position[2] = {point.getPositionWorldOnA(), point.getPositionWorldOnB()};
  // Per side J M^-1 J^T (summed as Bullet: side A's, then side B's, then
  // the softness), and the relative velocity in one running sum as Bullet's.
  btScalar side_inverse_mass[2] = {0, 0}, velocity = 0;
  bool from_basis = false, solved = false;
  for (int s = 0; s < 2; ++s) {
    ContactSide& side = sides_[s];
    if (!side.body) continue;
    const int ndof = side.ndof;
    const btVector3 link_direction = s == 0 ? direction : -direction;
    const btVector3 moment = (position[s] - side.origin).cross(link_direction);
    const btScalar weight[6] = {moment.x(),         moment.y(),         moment.z(),
                                link_direction.x(), link_direction.y(), link_direction.z()};
    const int block = deltaVelocityBlock(side.body, m_data);
    const int index = m_data.m_jacobians.size();
    m_data.m_jacobians.resize(index + ndof);
    m_data.m_deltaVelocitiesUnitImpulse.resize(index + ndof);
    btScalar* jacobian = &m_data.m_jacobians[index];
    btScalar* response = &m_data.m_deltaVelocitiesUnitImpulse[index];
    combineBasis(weight, &side.jacobian[0], ndof, jacobian);
    if (side.basis) {
      combineBasis(weight, &side.response[0], ndof, response);
      from_basis = true;
    } else {
      side.inertia->solve(jacobian, response, side.inertia->chainOf(side.link));
      solved = true;
    }
    if (s == 0) {
      row.m_deltaVelAindex = block;
      row.m_jacAindex = index;
    } else {
      row.m_deltaVelBindex = block;
      row.m_jacBindex = index;
    }
    const btScalar* qdot = side.body->getVelocityVector();
    for (int i = 0; i < ndof; ++i) {
      side_inverse_mass[s] += jacobian[i] * response[i];
      velocity += qdot[i] * jacobian[i];
    }
  }
  basis_rows_ += from_basis;
  solved_rows_ += solved;
  two_articulation_rows_ += sides_[0].body && sides_[1].body;

  // Lever arms and normals as the solver's feedback and rigid-body paths
  // read them: from each link's origin, or the static body's.
  const btVector3 arm_a = position[0] - sides_[0].origin;
  const btVector3 arm_b = position[1] - sides_[1].origin;
  row.m_relpos1CrossNormal = arm_a.cross(direction);
  row.m_contactNormal1 = direction;
  row.m_relpos2CrossNormal = -arm_b.cross(direction);
  row.m_contactNormal2 = -direction;
  row.m_angularComponentA.setZero();
  row.m_angularComponentB.setZero();

  // The velocity error with restitution and Baumgarte stabilisation, and
  // the impulse bounds.
  const btScalar dt = info.m_timeStep;
  const btScalar cfm = (friction ? info.m_frictionCFM : info.m_globalCfm) * (btScalar(1) / dt);
  const btScalar erp = friction ? info.m_frictionERP : info.m_erp2;
  const btScalar denominator = side_inverse_mass[0] + side_inverse_mass[1] + cfm;
  row.m_jacDiagABInv = denominator > SIMD_EPSILON ? info.m_sor / denominator : btScalar(0);
  row.m_friction = point.m_combinedFriction;
  btScalar velocity_error = -velocity, position_error = 0;
  if (!friction) {
    const btScalar bounce = restitutionCurve(velocity, point.m_combinedRestitution,
                                             info.m_restitutionVelocityThreshold);
    if (bounce > 0) velocity_error += bounce;
    const btScalar distance = point.getDistance() + info.m_linearSlop;
    if (distance > 0)
      velocity_error -= distance / dt;  // separated: close the gap this step, no push
    else
      position_error = -distance * erp / dt;
  }
  row.m_rhs = position_error * row.m_jacDiagABInv + velocity_error * row.m_jacDiagABInv;
  row.m_rhsPenetration = 0;
  row.m_lowerLimit = friction ? -row.m_friction : btScalar(0);
  row.m_upperLimit = friction ? row.m_friction : btScalar(1e10f);
  row.m_cfm = cfm * row.m_jacDiagABInv;
  row.m_appliedImpulse = 0;
  row.m_appliedPushImpulse = 0;
}

btScalar ArticulationSolver::rowVelocity(const btMultiBodySolverConstraint& row) {
  // One side: an articulation through its Jacobian, a rigid body through
  // the row's normal and lever arm, a static body not at all.
  auto side = [&](const btMultiBody* body, int jacobian, int block, int solver_body,
                  const btVector3& normal, const btVector3& arm) -> btScalar {
    if (body)
      return dot(&m_data.m_jacobians[jacobian], &m_data.m_deltaVelocities[block],
                 body->getNumDofs() + 6);
    if (solver_body < 0) return 0;
    btSolverBody& b = m_tmpSolverBodyPool[solver_body];
    return normal.dot(b.internalGetDeltaLinearVelocity()) +
           arm.dot(b.internalGetDeltaAngularVelocity());
  };
  return side(row.m_multiBodyA, row.m_jacAindex, row.m_deltaVelAindex, row.m_solverBodyIdA,
              row.m_contactNormal1, row.m_relpos1CrossNormal) +
         side(row.m_multiBodyB, row.m_jacBindex, row.m_deltaVelBindex, row.m_solverBodyIdB,
              row.m_contactNormal2, row.m_relpos2CrossNormal);
}

void ArticulationSolver::applyImpulse(const btMultiBodySolverConstraint& row, btScalar impulse) {
  // One side: an articulation's velocity changes through its response, a
  // rigid body's through the row's normal and angular component.
  auto side = [&](const btMultiBody* body, int response, int block, int solver_body,
                  const btVector3& normal, const btVector3& angular) {
    if (body) {
      const btScalar* r = &m_data.m_deltaVelocitiesUnitImpulse[response];
      btScalar* dv = &m_data.m_deltaVelocities[block];
      const int n = body->getNumDofs() + 6;
      for (int i = 0; i < n; ++i) dv[i] += r[i] * impulse;
    } else if (solver_body >= 0) {
      btSolverBody& b = m_tmpSolverBodyPool[solver_body];
      b.internalApplyImpulse(normal * b.internalGetInvMass(), angular, impulse);
    }
  };
  side(row.m_multiBodyA, row.m_jacAindex, row.m_deltaVelAindex, row.m_solverBodyIdA,
       row.m_contactNormal1, row.m_angularComponentA);
  side(row.m_multiBodyB, row.m_jacBindex, row.m_deltaVelBindex, row.m_solverBodyIdB,
       row.m_contactNormal2, row.m_angularComponentB);
}

void ArticulationSolver::findJointRows() {
  joint_rows_.resize(static_cast<size_t>(m_multiBodyNonContactConstraints.size()));
  for (int j = 0; j < m_multiBodyNonContactConstraints.size(); ++j) {
    const btMultiBodySolverConstraint& row = m_multiBodyNonContactConstraints[j];
    JointRow& joint = joint_rows_[static_cast<size_t>(j)];
    joint.sparse = false;
    if (!row.m_multiBodyA || row.m_multiBodyB != row.m_multiBodyA) continue;
    joint.envelope_slope = 0;
    if (row.m_orgConstraint &&
        row.m_orgConstraint->getConstraintType() == MULTIBODY_CONSTRAINT_1DOF_JOINT_MOTOR) {
      // An implicit servo's row (the engine's ServoConstraint, the only joint
      // motor here): its joint's coordinate on side A, nothing on side B, and
      // with a slope its motor's envelope (the bounds at no other impulse).
      joint.sparse = true;
      joint.coordinate_a = 6 + row.m_multiBodyA->getLink(row.m_linkA).m_dofOffset;
      joint.value_a = m_data.m_jacobians[row.m_jacAindex + joint.coordinate_a];
      joint.coordinate_b = 0;
      joint.value_b = 0;
      joint.response_b = false;
      if (row.m_friction > 0) {
        joint.envelope_slope = row.m_friction;
        joint.upper = row.m_upperLimit;
        joint.lower = row.m_lowerLimit;
        joint.inv_mass = row.m_rhsPenetration;
      }
      continue;
    }
    const int n = row.m_multiBodyA->getNumDofs() + 6;
    // At most one entry per side: the coordinate and its value.
    auto single = [&](int index, int& coordinate, btScalar& value) {
      const btScalar* jacobian = &m_data.m_jacobians[index];
      coordinate = 0;
      value = 0;
      int entries = 0;
      for (int i = 0; i < n; ++i)
        if (jacobian[i] != 0) {
          coordinate = i;
          value = jacobian[i];
          ++entries;
        }
      return entries <= 1;
    };
    if (!single(row.m_jacAindex, joint.coordinate_a, joint.value_a) ||
        !single(row.m_jacBindex, joint.coordinate_b, joint.value_b))
      continue;
    joint.sparse = true;
    const btScalar* response_b = &m_data.m_deltaVelocitiesUnitImpulse[row.m_jacBindex];
    joint.response_b = false;
    for (int i = 0; i < n; ++i) joint.response_b = joint.response_b || response_b[i] != 0;
  }
}

btScalar ArticulationSolver::resolveNonContactRow(int index) {
  btMultiBodySolverConstraint& row = m_multiBodyNonContactConstraints[index];
  const JointRow& joint = joint_rows_[static_cast<size_t>(index)];
  if (!joint.sparse) return resolveRow(row);
  // A joint row (servo, gear, limit): its velocity from one coordinate per
  // side, its impulse applied through the responses that are not zero. The
  // same numbers as the dense sums, whose other terms are all zero.
  const btScalar* dv_a = &m_data.m_deltaVelocities[row.m_deltaVelAindex];
  const btScalar* dv_b = &m_data.m_deltaVelocities[row.m_deltaVelBindex];
  const btScalar velocity =
      joint.value_a * dv_a[joint.coordinate_a] + joint.value_b * dv_b[joint.coordinate_b];
  if (joint.envelope_slope > 0) {
    const btScalar others = velocity - joint.inv_mass * btScalar(row.m_appliedImpulse);
    row.m_upperLimit = joint.upper - joint.envelope_slope * others;
    row.m_lowerLimit = joint.lower - joint.envelope_slope * others;
  }
  const btScalar delta = clampedUpdate(row, velocity);
  const int n = row.m_multiBodyA->getNumDofs() + 6;
  auto apply = [&](int response_index, int block) {
    const btScalar* r = &m_data.m_deltaVelocitiesUnitImpulse[response_index];
    btScalar* dv = &m_data.m_deltaVelocities[block];
    for (int i = 0; i < n; ++i) dv[i] += r[i] * delta;
  };
  apply(row.m_jacAindex, row.m_deltaVelAindex);
  if (joint.response_b) apply(row.m_jacBindex, row.m_deltaVelBindex);
  touched(row);
  return delta / row.m_jacDiagABInv;
}

btScalar ArticulationSolver::clampedUpdate(btMultiBodySolverConstraint& row, btScalar velocity) {
  // Projected Gauss-Seidel: the unclamped update, clamped to the row's bounds.
  btScalar delta = unclampedDelta(row, velocity);
  const btScalar total = btScalar(row.m_appliedImpulse) + delta;
  btScalar bounded = total;
  if (total < row.m_lowerLimit)
    bounded = row.m_lowerLimit;
  else if (total > row.m_upperLimit)
    bounded = row.m_upperLimit;
  if (bounded != total) delta = bounded - btScalar(row.m_appliedImpulse);
  row.m_appliedImpulse = bounded;
  return delta;
}

btScalar ArticulationSolver::resolveRow(btMultiBodySolverConstraint& row) {
  const btScalar delta = clampedUpdate(row, rowVelocity(row));
  applyImpulse(row, delta);
  touched(row);
  return delta / row.m_jacDiagABInv;
}

btScalar ArticulationSolver::resolveFrictionPair(btMultiBodySolverConstraint& a,
                                                 btMultiBodySolverConstraint& b) {
  // Both rows' unclamped updates from the same velocities, then the pair
  // scaled back onto the circle of radius mu N (the rows' bounds) along its
  // own direction, as Bullet's implicit friction cone.
  btScalar delta_a = unclampedDelta(a, rowVelocity(a));
  btScalar delta_b = unclampedDelta(b, rowVelocity(b));
  btScalar total_a = btScalar(a.m_appliedImpulse) + delta_a;
  btScalar total_b = btScalar(b.m_appliedImpulse) + delta_b;
  if (total_a * total_a + total_b * total_b >= a.m_lowerLimit * b.m_lowerLimit) {
    const btScalar angle = btAtan2(total_a, total_b);
    const btScalar limit_a = btFabs(a.m_lowerLimit * btSin(angle));
    const btScalar limit_b = btFabs(b.m_lowerLimit * btCos(angle));
    const btScalar clamped_a = btMin(btMax(total_a, -limit_a), limit_a);
    const btScalar clamped_b = btMin(btMax(total_b, -limit_b), limit_b);
    if (clamped_a != total_a) delta_a = clamped_a - btScalar(a.m_appliedImpulse);
    if (clamped_b != total_b) delta_b = clamped_b - btScalar(b.m_appliedImpulse);
    total_a = clamped_a;
    total_b = clamped_b;
  }
  a.m_appliedImpulse = total_a;
  b.m_appliedImpulse = total_b;
  applyImpulse(a, delta_a);
  applyImpulse(b, delta_b);
  touched(a);
  touched(b);
  return delta_a / a.m_jacDiagABInv + delta_b / b.m_jacDiagABInv;
}

btScalar ArticulationSolver::solveSingleIteration(
    int iteration, btCollisionObject** bodies, int num_bodies, btPersistentManifold** manifolds,
    int num_manifolds, btTypedConstraint** constraints, int num_constraints,
    const btContactSolverInfo& info, btIDebugDraw* debug_draw) {
  if (!lean(info))
    return btMultiBodyConstraintSolver::solveSingleIteration(iteration, bodies, num_bodies,
                                                             manifolds, num_manifolds, constraints,
                                                             num_constraints, info, debug_draw);
  // Rigid bodies against each other (the ball on the carpet): Bullet's.
  btScalar residual = btSequentialImpulseConstraintSolver::solveSingleIteration(
      iteration, bodies, num_bodies, manifolds, num_manifolds, constraints, num_constraints, info,
      debug_draw);
  auto track = [&residual](btScalar change) { residual = btMax(residual, change * change); };

  // The articulations' own constraints, in alternating order.
  btScalar own = 0;
  const int num_own = m_multiBodyNonContactConstraints.size();
  for (int inner = 0; inner < info.m_numNonContactInnerIterations; ++inner) {
    own = 0;
    for (int j = 0; j < num_own; ++j) {
      const btScalar change = resolveNonContactRow((iteration & 1) ? j : num_own - 1 - j);
      own = btMax(own, change * change);
    }
  }
  residual = btMax(residual, own);
  if (iteration >= info.m_numIterations) return residual;

  for (int j = 0; j < m_multiBodyNormalContactConstraints.size(); ++j)
    track(resolveRow(m_multiBodyNormalContactConstraints[j]));

  // Friction bounded by its contact's normal impulse.
  auto bound = [this](btMultiBodySolverConstraint& row) {
    const btScalar normal =
        m_multiBodyNormalContactConstraints[row.m_frictionIndex].m_appliedImpulse;
    row.m_lowerLimit = -(row.m_friction * normal);
    row.m_upperLimit = row.m_friction * normal;
    return normal;
  };
  if ((info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS) &&
      !(info.m_solverMode & SOLVER_DISABLE_IMPLICIT_CONE_FRICTION)) {
    for (int j = 0; j < m_multiBodySpinningFrictionContactConstraints.size(); ++j) {
      btMultiBodySolverConstraint& row = m_multiBodySpinningFrictionContactConstraints[j];
      if (bound(row) > 0) track(resolveRow(row));
    }
    for (int j = 0; j + 1 < m_multiBodyTorsionalFrictionContactConstraints.size(); j += 2) {
      btMultiBodySolverConstraint& a = m_multiBodyTorsionalFrictionContactConstraints[j];
      btMultiBodySolverConstraint& b = m_multiBodyTorsionalFrictionContactConstraints[j + 1];
      if (a.m_frictionIndex != b.m_frictionIndex) continue;
      if (bound(a) > 0) {
        bound(b);
        track(resolveFrictionPair(a, b));
      }
    }
    for (int j = 0; j + 1 < m_multiBodyFrictionContactConstraints.size(); j += 2) {
      btMultiBodySolverConstraint& a = m_multiBodyFrictionContactConstraints[j];
      btMultiBodySolverConstraint& b = m_multiBodyFrictionContactConstraints[j + 1];
      if (a.m_frictionIndex != b.m_frictionIndex) continue;
      bound(a);
      bound(b);
      track(resolveFrictionPair(a, b));
    }
  } else {
    for (int j = 0; j < m_multiBodyFrictionContactConstraints.size(); ++j) {
      btMultiBodySolverConstraint& row = m_multiBodyFrictionContactConstraints[j];
      if (bound(row) > 0) track(resolveRow(row));
    }
  }
  return residual;
}

btScalar ArticulationSolver::solveGroupCacheFriendlyIterations(
    btCollisionObject** bodies, int num_bodies, btPersistentManifold** manifolds, int num_manifolds,
    btTypedConstraint** constraints, int num_constraints, const btContactSolverInfo& info,
    btIDebugDraw* debug_draw) {
  if (lean(info)) findJointRows();
  const btScalar residual = btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyIterations(
      bodies, num_bodies, manifolds, num_manifolds, constraints, num_constraints, info, debug_draw);
  if (!lean(info)) return residual;
  // Each articulation's accumulated velocity change, once, where Bullet
  // would have added it row by row.
  applied_.assign(static_cast<size_t>(m_data.m_deltaVelocities.size()), 0);
  auto add = [&](btMultiBody* body, int block) {
    if (!body || applied_[static_cast<size_t>(block)]) return;
    applied_[static_cast<size_t>(block)] = 1;
    body->applyDeltaVeeMultiDof2(&m_data.m_deltaVelocities[block], 1);
  };
  for (const btMultiBodyConstraintArray* rows :
       {&m_multiBodyNonContactConstraints, &m_multiBodyNormalContactConstraints,
        &m_multiBodyFrictionContactConstraints, &m_multiBodyTorsionalFrictionContactConstraints,
        &m_multiBodySpinningFrictionContactConstraints})
    for (int j = 0; j < rows->size(); ++j) {
      add((*rows)[j].m_multiBodyA, (*rows)[j].m_deltaVelAindex);
      add((*rows)[j].m_multiBodyB, (*rows)[j].m_deltaVelBindex);
    }
  return residual;
}

}  // namespace simsoccer::engine

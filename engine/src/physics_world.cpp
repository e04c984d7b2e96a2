#include "simsoccer/engine/physics_world.hpp"

#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyInplaceSolverIslandCallback.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

#include "articulation_inertia.hpp"
#include "articulation_solver.hpp"
#include "island_solver.hpp"

namespace simsoccer::engine {
namespace {

using Clock = std::chrono::steady_clock;

btVector3 toBt(const Vec3& v) {
  return btVector3(static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()),
                   static_cast<btScalar>(v.z()));
}
Vec3 fromBt(const btVector3& v) {
  return Vec3(v.x(), v.y(), v.z());
}
btQuaternion toBt(const Quat& q) {
  return btQuaternion(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()),
                      static_cast<btScalar>(q.z()), static_cast<btScalar>(q.w()));
}
Quat fromBt(const btQuaternion& q) {
  return Quat(q.w(), q.x(), q.y(), q.z());
}
btTransform toBt(const Pose& p) {
  return btTransform(toBt(Quat(p.linear()).normalized()), toBt(Vec3(p.translation())));
}
Pose fromBt(const btTransform& t) {
  Pose p = Pose::Identity();
  p.linear() = fromBt(t.getRotation()).normalized().toRotationMatrix();
  p.translation() = fromBt(t.getOrigin());
  return p;
}

// Marks free rigid bodies (their BodyId is in user index 2).
constexpr int kRigidBodyTag = -7;
// User index 3 of the ground plane (addGround: z = 0), which the near callback recognises.
constexpr int kGroundTag = -8;

// Small margins: Bullet's default 4 cm would round a 35 mm foot box away.
constexpr btScalar kBoxMargin = 0.001f;
constexpr btScalar kCylinderMargin = 0.004f;

// A Bullet shape for one primitive, centred on its own frame.
std::unique_ptr<btCollisionShape> makePrimitive(const Shape& s) {
  switch (s.type) {
    case ShapeType::Sphere:
      return std::make_unique<btSphereShape>(static_cast<btScalar>(s.radius));
    case ShapeType::Box: {
      auto box = std::make_unique<btBoxShape>(toBt(Vec3(0.5 * s.extents)));
      box->setMargin(kBoxMargin);
      return box;
    }
    case ShapeType::Capsule:
      // Bullet's capsule height excludes the two hemispherical caps.
      return std::make_unique<btCapsuleShapeZ>(static_cast<btScalar>(s.radius),
                                               static_cast<btScalar>(s.length - 2.0 * s.radius));
    case ShapeType::Cylinder: {
      auto cyl = std::make_unique<btCylinderShapeZ>(
          btVector3(static_cast<btScalar>(s.radius), static_cast<btScalar>(s.radius),
                    static_cast<btScalar>(0.5 * s.length)));
      cyl->setMargin(kCylinderMargin);
      return cyl;
    }
  }
  throw std::logic_error("unknown shape type");
}

void applyMaterial(btCollisionObject* o, const Material& m) {
  o->setFriction(static_cast<btScalar>(m.friction));
  o->setRollingFriction(static_cast<btScalar>(m.rolling_friction));
  o->setSpinningFriction(static_cast<btScalar>(m.spinning_friction));
  o->setRestitution(static_cast<btScalar>(m.restitution));
}

// Rejects pairs of colliders that belong to the same robot at the broadphase,
// so self-collision costs nothing. The robot's group is the user index
// (-1 for anything that is not part of a robot).
struct SameRobotFilter : btOverlapFilterCallback {
  bool needBroadphaseCollision(btBroadphaseProxy* p0, btBroadphaseProxy* p1) const override {
    if (!(p0->m_collisionFilterGroup & p1->m_collisionFilterMask) ||
        !(p1->m_collisionFilterGroup & p0->m_collisionFilterMask))
      return false;
    const auto* a = static_cast<const btCollisionObject*>(p0->m_clientObject);
    const auto* b = static_cast<const btCollisionObject*>(p1->m_clientObject);
    const int ga = a->getUserIndex();
    return ga < 0 || ga != b->getUserIndex();
  }
};

// Bullet's near callback without the narrowphase of a robot link clearly above the ground
// plane. The plane's bounding box is infinite, so every link of every robot pairs with it
// every step, and Bullet tests each of the link's shapes against it, mostly to find nothing:
// most of a robot is far above the carpet. A link whose bounding box (its shapes' margins
// included) is higher above the plane than any of the pair's contact breaking thresholds can
// have no point with it, and Bullet's refresh would drop every point its manifolds still
// hold; so the manifolds are emptied and nothing else runs. Only a pair processed before is
// skipped: its manifolds were made at its first step, in Bullet's order (which decides the
// solver's row order), so the state is the same bit for bit.
void groundCullingNearCallback(btBroadphasePair& pair, btCollisionDispatcher& dispatcher,
                               const btDispatcherInfo& info) {
  if (pair.m_algorithm) {
    auto* a = static_cast<btCollisionObject*>(pair.m_pProxy0->m_clientObject);
    auto* b = static_cast<btCollisionObject*>(pair.m_pProxy1->m_clientObject);
    const btCollisionObject* link = a->getUserIndex3() == kGroundTag   ? b
                                    : b->getUserIndex3() == kGroundTag ? a
                                                                       : nullptr;
    if (link && btMultiBodyLinkCollider::upcast(link) && dispatcher.needsCollision(a, b)) {
      btVector3 low, high;
      link->getCollisionShape()->getAabb(link->getWorldTransform(), low, high);
      const btScalar height = low.z();  // above the ground plane, z = 0
      thread_local btManifoldArray manifolds;
      manifolds.resize(0);
      pair.m_algorithm->getAllContactManifolds(manifolds);
      bool clear = manifolds.size() > 0;
      for (int i = 0; i < manifolds.size() && clear; ++i)
        clear = height > manifolds[i]->getContactBreakingThreshold() + btScalar(1e-3);
      if (clear) {
        for (int i = 0; i < manifolds.size(); ++i)
          if (manifolds[i]->getNumContacts() > 0) manifolds[i]->clearManifold();
        return;
      }
    }
  }
  btCollisionDispatcher::defaultNearCallback(pair, dispatcher, info);
}

// btMultiBodyDynamicsWorld with wall-clock timers around Bullet's own stages.
class TimedMultiBodyWorld : public btMultiBodyDynamicsWorld {
 public:
  using btMultiBodyDynamicsWorld::btMultiBodyDynamicsWorld;
  StageTimes* times = nullptr;               // null: timers off
  ParallelIslandSolver* islands = nullptr;   // null: Bullet solves the islands in turn
  ArticulationInertias* inertias = nullptr;  // null: Bullet's pass for every row's response

  void performDiscreteCollisionDetection() override {
    timed(&StageTimes::collision_s,
          [&] { btMultiBodyDynamicsWorld::performDiscreteCollisionDetection(); });
  }
  void solveExternalForces(btContactSolverInfo& info) override {
    timed(&StageTimes::dynamics_s, [&] { btMultiBodyDynamicsWorld::solveExternalForces(info); });
  }
  // Bullet solves islands in batches while it builds them, so the solver's
  // share is the whole constraint stage less the forward dynamics inside it.
  void solveConstraints(btContactSolverInfo& info) override {
    const double dynamics_before = times ? times->dynamics_s : 0.0;
    if (inertias) inertias->newStep();  // factorised again at the first row of each
    timed(&StageTimes::solver_s, [&] {
      // Bullet's own loop where batches could share state (a randomised row
      // order: one seed across batches; islands not split: one group), and
      // without the engine's loop (bullet_solver with one thread).
      if (!islands || (info.m_solverMode & SOLVER_RANDMIZE_ORDER) ||
          !m_islandManager->getSplitIslands()) {
        btMultiBodyDynamicsWorld::solveConstraints(info);
        if (islands) islands->clear();  // no batches this step
        return;
      }
      // Bullet's three stages, the islands solved on the threads in between:
      // what precedes the forward dynamics (which also sorts the constraints
      // by island), the islands, each batch's forward dynamics on its thread
      // just before it is solved, and what follows Bullet's last batch
      // (joint feedback, the solver's velocity changes applied; its own
      // batch is empty). The forward dynamics of a robot reads and writes
      // that robot alone, so where it runs changes nothing in the result.
      timed(&StageTimes::dynamics_s, [&] { prepareConstraints(info); });
      islands->setup(
          info, m_sortedConstraints.size() ? &m_sortedConstraints[0] : nullptr,
          m_sortedConstraints.size(),
          m_sortedMultiBodyConstraints.size() ? &m_sortedMultiBodyConstraints[0] : nullptr,
          m_sortedMultiBodyConstraints.size(), islands_of_sorted_.data());
      m_islandManager->buildAndProcessIslands(getCollisionWorld()->getDispatcher(),
                                              getCollisionWorld(), islands);
      dynamics_done_.assign(static_cast<size_t>(m_multiBodies.size()), 0);
      scratch_.resize(static_cast<size_t>(islands->threadCount()));
      const ParallelIslandSolver::Prologue prologue = [&](btCollisionObject** bodies, int n,
                                                          int thread) {
        for (int i = 0; i < n; ++i)
          if (const btMultiBodyLinkCollider* link = btMultiBodyLinkCollider::upcast(bodies[i]))
            forwardDynamics(link->m_multiBody, info, thread);
      };
      islands->solve(getDebugDrawer(), getCollisionWorld()->getDispatcher(), &prologue);
      for (int i = 0; i < m_multiBodies.size(); ++i)  // those in no island
        forwardDynamics(m_multiBodies[i], info, 0);
      solveInternalConstraints(info);
    });
    if (times) times->solver_s -= times->dynamics_s - dynamics_before;
  }
  void integrateTransforms(btScalar dt) override {
    timed(&StageTimes::integrate_s, [&] { btMultiBodyDynamicsWorld::integrateTransforms(dt); });
  }
  // Bullet's multibody prediction integrates every robot a step ahead only to set its links'
  // interpolation transforms, which continuous collision of rigid bodies alone reads (the
  // links are discrete): the rigid bodies' prediction is kept, the robots' skipped.
  void predictUnconstraintMotion(btScalar dt) override {
    btDiscreteDynamicsWorld::predictUnconstraintMotion(dt);
  }

 private:
  // Per solver thread: Bullet's scratch arrays for the forward dynamics.
  struct Scratch {
    btAlignedObjectArray<btScalar> r;
    btAlignedObjectArray<btVector3> v;
    btAlignedObjectArray<btMatrix3x3> m;
  };
  std::vector<Scratch> scratch_;
  std::vector<uint8_t> dynamics_done_;  // per multibody (its user index), this step
  // Per multibody: asleep when the step's constraints were prepared (where
  // Bullet's own loop decides; building the islands can change it).
  std::vector<uint8_t> sleeping_;
  struct Keyed {
    btMultiBodyConstraint* constraint;
    int island;
  };
  btAlignedObjectArray<Keyed> keyed_;
  std::vector<int> islands_of_sorted_;  // island of each of m_sortedMultiBodyConstraints

  // btMultiBodyDynamicsWorld::solveExternalForces without its forward-dynamics
  // loop (gravity and force clearing are Bullet's virtual applyGravity and
  // clearForces in this build, BT_USE_VIRTUAL_CLEARFORCES_AND_GRAVITY).
  void prepareConstraints(btContactSolverInfo& info) {
    sleeping_.assign(static_cast<size_t>(m_multiBodies.size()), 0);
    for (int i = 0; i < m_multiBodies.size(); ++i) {
      const btMultiBody* body = m_multiBodies[i];
      bool sleeping = body->getBaseCollider() &&
                      body->getBaseCollider()->getActivationState() == ISLAND_SLEEPING;
      for (int b = 0; b < body->getNumLinks(); ++b)
        if (body->getLink(b).m_collider &&
            body->getLink(b).m_collider->getActivationState() == ISLAND_SLEEPING)
          sleeping = true;
      sleeping_[static_cast<size_t>(body->getUserIndex())] = sleeping;
    }
    forwardKinematics();
    clearMultiBodyConstraintForces();
    m_sortedConstraints.resize(m_constraints.size());
    for (int i = 0; i < m_constraints.size(); ++i) m_sortedConstraints[i] = m_constraints[i];
    m_sortedConstraints.quickSort(btSortConstraintOnIslandPredicate2());
    // By island, each constraint asked for its island once (Bullet's
    // predicate asks twice per comparison): the same comparisons on the same
    // keys, so Bullet's quick sort gives the same order.
    const int n = m_multiBodyConstraints.size();
    keyed_.resize(n);
    for (int i = 0; i < n; ++i)
      keyed_[i] = {m_multiBodyConstraints[i],
                   btGetMultiBodyConstraintIslandId(m_multiBodyConstraints[i])};
    keyed_.quickSort([](const Keyed& a, const Keyed& b) { return a.island < b.island; });
    m_sortedMultiBodyConstraints.resize(n);
    islands_of_sorted_.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      m_sortedMultiBodyConstraints[i] = keyed_[i].constraint;
      islands_of_sorted_[static_cast<size_t>(i)] = keyed_[i].island;
    }
    m_solverMultiBodyIslandCallback->setup(
        &info, m_sortedConstraints.size() ? &m_sortedConstraints[0] : nullptr,
        m_sortedConstraints.size(),
        m_sortedMultiBodyConstraints.size() ? &m_sortedMultiBodyConstraints[0] : nullptr,
        m_sortedMultiBodyConstraints.size(), getDebugDrawer());
    m_constraintSolver->prepareSolve(getCollisionWorld()->getNumCollisionObjects(),
                                     getCollisionWorld()->getDispatcher()->getNumManifolds());
  }

  // One multibody's step of Bullet's forward-dynamics loop, once per step.
  void forwardDynamics(btMultiBody* body, const btContactSolverInfo& info, int thread) {
    const auto index = static_cast<size_t>(body->getUserIndex());
    if (dynamics_done_[index]) return;
    dynamics_done_[index] = 1;
    if (sleeping_[index]) return;
    if (body->isUsingRK4Integration())
      throw std::logic_error("RK4 multibody integration is not supported");
    Scratch& s = scratch_[static_cast<size_t>(thread)];
    s.r.resize(body->getNumLinks() + 1);
    s.v.resize(body->getNumLinks() + 1);
    s.m.resize(body->getNumLinks() + 1);
    body->computeAccelerationsArticulatedBodyAlgorithmMultiDof(
        info.m_timeStep, s.r, s.v, s.m, /*isConstraintPass=*/false,
        getSolverInfo().m_jointFeedbackInWorldSpace, getSolverInfo().m_jointFeedbackInJointFrame);
  }

  template <class F>
  void timed(double StageTimes::*field, F&& f) {
    if (!times) {
      f();
      return;
    }
    const auto t0 = Clock::now();
    f();
    times->*field += std::chrono::duration<double>(Clock::now() - t0).count();
  }
};

// A row of an articulation's own constraint on its joints (both sides the
// articulation, as Bullet's joint motors and gears build theirs): the common
// fields and the torque axes, the articulation's delta-velocity block for
// both sides, and room for a Jacobian and a response per side (side A's
// first); the caller fills those and the bias, softness and bounds.
btMultiBodySolverConstraint& addJointRow(btMultiBodyConstraintArray& rows,
                                         btMultiBodyJacobianData& data, btMultiBody* mb, int link_a,
                                         int link_b, btMultiBodyConstraint* constraint) {
  const int ndof = mb->getNumDofs() + 6;
  btMultiBodySolverConstraint& row = rows.expandNonInitializing();
  row.m_multiBodyA = row.m_multiBodyB = mb;
  row.m_linkA = link_a;
  row.m_linkB = link_b;
  row.m_solverBodyIdA = row.m_solverBodyIdB = data.m_fixedBodyId;
  row.m_orgConstraint = constraint;
  row.m_orgDofIndex = 0;
  row.m_deltaVelAindex = row.m_deltaVelBindex = deltaVelocityBlock(mb, data);
  row.m_jacAindex = data.m_jacobians.size();
  row.m_jacBindex = row.m_jacAindex + ndof;
  data.m_jacobians.resize(row.m_jacAindex + 2 * ndof);
  data.m_deltaVelocitiesUnitImpulse.resize(row.m_jacAindex + 2 * ndof);
  row.m_rhsPenetration = 0;
  row.m_friction = 0;
  row.m_appliedImpulse = 0;
  row.m_appliedPushImpulse = 0;
  // As Bullet's motor: the impulse acts as a torque about joint A's axis on
  // its link and as the reaction on the other side.
  const btVector3 axis = quatRotate(mb->getLink(link_a).m_cachedWorldTransform.getRotation(),
                                    mb->getLink(link_a).m_axes[0].m_topVec);
  row.m_contactNormal1.setZero();
  row.m_contactNormal2.setZero();
  row.m_relpos1CrossNormal = axis;
  row.m_relpos2CrossNormal = -axis;
  row.m_angularComponentA.setZero();
  row.m_angularComponentB.setZero();
  return row;
}

// One joint servo as a row of Bullet's constraint solver: a joint-velocity
// row (as Bullet's btMultiBodyJointMotor, whose island and finalize code it
// reuses) made soft with the servo's compliance gamma, so that the solver
// applies the implicit spring-damper of JointServoBatch with the real
// articulated inertia, its impulse bounded by the motor envelope. No row
// while the servo is limp. The row is filled here rather than by Bullet's
// fillMultiBodyConstraint, which runs a second articulated-body pass for the
// parent side: its Jacobian is zero for a joint row, so its response is too,
// and that pass was half the cost of the servos.
class ServoConstraint : public btMultiBodyJointMotor {
 public:
  // `inertias` null: the response from Bullet's articulated-body pass.
  // `envelope_in_solver`: see PhysicsSettings.
  ServoConstraint(btMultiBody* body, int link, const JointServoBatch& batch, size_t servo,
                  ArticulationInertias* inertias, bool envelope_in_solver)
      : btMultiBodyJointMotor(body, link, 0, 1),
        batch_(batch),
        servo_(servo),
        inertias_(inertias),
        envelope_in_solver_(envelope_in_solver) {}

  // The impulse applied in the last step (0 without a row), N m s.
  btScalar impulse() { return row_made_ ? getAppliedImpulse(0) : btScalar(0); }
  void startStep() { row_made_ = false; }
  size_t servo() const { return servo_; }  // its row in the servo batch

  void createConstraintRows(btMultiBodyConstraintArray& rows, btMultiBodyJacobianData& data,
                            const btContactSolverInfo& info) override {
    const JointServoBatch::Row r = batch_.row(servo_);
    if (!r.active) return;
    if (m_numDofsFinalized != m_jacSizeBoth) finalizeMultiDof();
    btMultiBody* mb = m_bodyA;
    const int ndof = mb->getNumDofs() + 6;
    btMultiBodySolverConstraint& row = addJointRow(rows, data, mb, m_linkA, m_linkB, this);
    // Jacobians: 1 at the joint's coordinate (side A), zero (side B).
    btScalar* jac = &data.m_jacobians[row.m_jacAindex];
    btScalar* response = &data.m_deltaVelocitiesUnitImpulse[row.m_jacAindex];
    const btScalar* own = jacobianA(0);
    for (int i = 0; i < ndof; ++i) {
      jac[i] = own[i];
      jac[ndof + i] = 0;
      response[ndof + i] = 0;
    }
    const int coordinate = 6 + mb->getLink(m_linkA).m_dofOffset;
    const ArticulationInertia* inertia = inertias_ ? inertias_->of(*mb) : nullptr;
    if (const btScalar* column = inertia ? inertia->column(coordinate) : nullptr)
      std::copy(column, column + ndof, response);  // solved with the robot's other servos
    else if (inertia)
      inertia->solve(jac, response, coordinate);
    else
      mb->calcAccelerationDeltasMultiDof(jac, response, data.scratch_r, data.scratch_v);
    const btScalar inv_mass = response[coordinate];  // J M^-1 J^T
    const btScalar velocity = mb->getJointVel(m_linkA);
    // Soft row: qdot' = beta / dt (target - q) - gamma (dt feedforward + p).
    const btScalar h = info.m_timeStep;
    const btScalar gamma = static_cast<btScalar>(r.gamma);
    btScalar goal = static_cast<btScalar>(r.beta / h * (r.target - mb->getJointPos(m_linkA)) -
                                          r.gamma * h * r.feedforward);
    if (r.bias != 0.0) goal += static_cast<btScalar>(r.bias);  // a command's velocity, torque
    const btScalar soft = btScalar(1) / (inv_mass + gamma);
    row.m_jacDiagABInv = soft;
    row.m_rhs = (goal - velocity) * soft;
    row.m_cfm = gamma * soft;
    if (inertias_ && envelope_in_solver_ && r.drive > 0.0) {
      // The engine's solver bounds the motor's torque on its torque-speed
      // line at the speed it solves for (JointServoBatch::Row::envelope; the
      // feedforward's impulse is in `velocity` already). It moves the bounds
      // with what the other rows add, reading the slope from m_friction and
      // inv_mass from m_rhsPenetration, which a joint row does not use
      // otherwise.
      const JointServoBatch::Row::ImpulseBounds b =
          r.envelope(h, inv_mass, velocity, h * r.feedforward);
      row.m_lowerLimit = static_cast<btScalar>(b.lower);
      row.m_upperLimit = static_cast<btScalar>(b.upper);
      row.m_friction = static_cast<btScalar>(b.slope);
      row.m_rhsPenetration = inv_mass;
    } else {
      row.m_lowerLimit = static_cast<btScalar>((r.lower - r.feedforward) * h);
      row.m_upperLimit = static_cast<btScalar>((r.upper - r.feedforward) * h);
    }
    row_made_ = true;
  }

 private:
  const JointServoBatch& batch_;
  size_t servo_;
  ArticulationInertias* inertias_;
  bool envelope_in_solver_;
  bool row_made_ = false;
};

// A mimic joint's gear row (Bullet's btMultiBodyGearConstraint: qdot_A +
// ratio qdot_B = 0 with its drift corrected, both joints of one
// articulation), filled as Bullet's fillMultiBodyConstraint fills it (the
// same fields, effective mass, bias and bounds) but with the two responses
// from the articulation's factorised inertia instead of two articulated-body
// passes. Without the factorisation (bullet_solver), Bullet's own rows.
class MimicConstraint : public btMultiBodyGearConstraint {
 public:
  // Bullet's gear between the joints of two links of one articulation.
  MimicConstraint(btMultiBody* body, int link_a, int link_b, ArticulationInertias* inertias)
      : btMultiBodyGearConstraint(body, link_a, body, link_b, btVector3(0, 0, 0),
                                  btVector3(0, 0, 0), btMatrix3x3::getIdentity(),
                                  btMatrix3x3::getIdentity()),
        inertias_(inertias) {}

  void createConstraintRows(btMultiBodyConstraintArray& rows, btMultiBodyJacobianData& data,
                            const btContactSolverInfo& info) override {
    btMultiBody* mb = m_bodyA;
    const ArticulationInertia* inertia = inertias_ ? inertias_->of(*mb) : nullptr;
    if (!inertia || m_gearAuxLink >= 0) {
      btMultiBodyGearConstraint::createConstraintRows(rows, data, info);
      return;
    }
    if (m_numDofsFinalized != m_jacSizeBoth) finalizeMultiDof();
    if (m_maxAppliedImpulse == 0) return;
    const int ndof = mb->getNumDofs() + 6;
    const int coordinate_a = 6 + mb->getLink(m_linkA).m_dofOffset;
    const int coordinate_b = 6 + mb->getLink(m_linkB).m_dofOffset;
    btMultiBodySolverConstraint& row = addJointRow(rows, data, mb, m_linkA, m_linkB, this);
    // Side A: 1 at joint A; side B: the ratio at joint B.
    btScalar* jac_a = &data.m_jacobians[row.m_jacAindex];
    btScalar* jac_b = jac_a + ndof;
    for (int i = 0; i < 2 * ndof; ++i) jac_a[i] = 0;
    jac_a[coordinate_a] = 1;
    jac_b[coordinate_b] = m_gearRatio;
    btScalar* response_a = &data.m_deltaVelocitiesUnitImpulse[row.m_jacAindex];
    inertia->solve(jac_a, response_a, coordinate_a);
    inertia->solve(jac_b, response_a + ndof, coordinate_b);
    // Bullet's sums: each side's J M^-1 J^T (no cross term between the two
    // sides of one body, as Bullet), its relative velocity and bias.
    btScalar denominator = 0, velocity = 0;
    const btScalar* qdot = mb->getVelocityVector();
    for (int i = 0; i < ndof; ++i) denominator += jac_a[i] * response_a[i];
    for (int i = 0; i < ndof; ++i) denominator += jac_b[i] * response_a[ndof + i];
    for (int i = 0; i < ndof; ++i) velocity += qdot[i] * jac_a[i];
    for (int i = 0; i < ndof; ++i) velocity += qdot[i] * jac_b[i];
    row.m_jacDiagABInv = denominator > SIMD_EPSILON ? btScalar(1) / denominator : btScalar(0);
    btScalar position_error = 0;
    if (m_erp != 0) {
      const btScalar difference = m_gearRatio * mb->getJointPos(m_linkB) + mb->getJointPos(m_linkA);
      position_error = -m_erp * (m_relativePositionTarget - difference);
    }
    const btScalar positional = -position_error * info.m_erp / info.m_timeStep;
    row.m_rhs = positional * row.m_jacDiagABInv + (btScalar(0) - velocity) * row.m_jacDiagABInv;
    row.m_cfm = 0;
    row.m_lowerLimit = -m_maxAppliedImpulse;
    row.m_upperLimit = m_maxAppliedImpulse;
  }

 private:
  ArticulationInertias* inertias_;
};

struct Articulation {
  std::shared_ptr<const ArticulatedModel> model;
  btMultiBody* body = nullptr;
  // Per link: the Bullet link frame (at the CoM, along the principal axes of
  // inertia) expressed in the link's joint frame.
  std::vector<Pose> bullet_in_joint;
  std::vector<Pose> joint_in_bullet;  // the inverses, for linkPose
  // Per joint: index into the servo batch, or -1 for a passive joint.
  std::vector<int> servo;
  // Bullet refreshes the links' cached world transforms only inside its
  // step, before integration; they are recomputed on the first read after.
  bool kinematics_stale = false;
  // Bullet's scratch arrays for forward kinematics, kept so that refreshing
  // allocates nothing after the first time.
  btAlignedObjectArray<btQuaternion> scratch_world_to_local;
  btAlignedObjectArray<btVector3> scratch_local_origin;
};

// Checks a model before any Bullet object is made from it.
void validateModel(const ArticulatedModel& model) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument("articulated model '" + model.name + "': " + what);
  };
  if (model.links.empty() || model.joints.size() + 1 != model.links.size())
    fail("needs one joint per non-root link");
  for (const Link& l : model.links)
    if (!(l.mass > 0.0)) fail("link '" + l.name + "' needs a mass > 0");
  for (const Motor& m : model.motors)
    if (!(m.no_load_speed > 0.0) || !(m.stall_torque > 0.0))
      fail("motor '" + m.name + "' needs stall torque and no-load speed > 0");
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& joint = model.joints[j];
    if (joint.child_link != static_cast<int>(j) + 1 || joint.parent_link < 0 ||
        joint.parent_link > static_cast<int>(j))
      fail("joint '" + joint.name + "' is not in tree order");
    if (!(joint.lower < joint.upper)) fail("joint '" + joint.name + "' has lower >= upper limit");
    if (joint.motor >= static_cast<int>(model.motors.size()))
      fail("joint '" + joint.name + "' names a motor that does not exist");
    if (joint.mimic_of >= 0) {
      if (joint.mimic_of >= static_cast<int>(model.joints.size()) ||
          joint.mimic_of == static_cast<int>(j) ||
          model.joints[static_cast<size_t>(joint.mimic_of)].mimic_of >= 0)
        fail("joint '" + joint.name + "' mimics an invalid joint");
      if (joint.motor >= 0) fail("mimic joint '" + joint.name + "' must not have its own motor");
      if (joint.mimic_multiplier == 0.0) fail("joint '" + joint.name + "' has mimic multiplier 0");
    }
  }
}

}  // namespace

struct PhysicsWorld::Impl {
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<ArticulationSolver> solver;
  std::unique_ptr<TimedMultiBodyWorld> world;
  std::unique_ptr<ParallelIslandSolver> islands;  // the batches, on solver_threads threads
  std::vector<ArticulationSolver*> all_solvers;   // the world's and each thread's
  ArticulationInertias inertias;                  // the articulations' (not with bullet_solver)
  SameRobotFilter filter;

  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> statics;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btMotionState>> motion_states;
  std::vector<std::unique_ptr<btMultiBody>> multibodies;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints;
  std::vector<Articulation> articulations;

  // Servo batch over all joints of all articulations, with its I/O arrays.
  JointServoBatch servos;
  std::vector<btMultiBody*> servo_body;
  std::vector<int> servo_link;
  // The implicit servos' rows (owned by `constraints`), with their servo index.
  std::vector<ServoConstraint*> servo_rows;
  std::vector<double> q, qdot;

  StageTimes times;

  btCollisionShape* keep(std::unique_ptr<btCollisionShape> s) {
    shapes.push_back(std::move(s));
    return shapes.back().get();
  }

  // A compound holding the link's primitives in its Bullet frame.
  btCollisionShape* linkShape(const Link& link, const Pose& bullet_in_joint) {
    auto compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/false,
                                                      static_cast<int>(link.shapes.size()));
    const Pose joint_in_bullet = bullet_in_joint.inverse();  // once per link, at build time
    for (const Shape& s : link.shapes) {
      btCollisionShape* child = keep(makePrimitive(s));
      compound->addChildShape(toBt(Pose(joint_in_bullet * s.pose)), child);
    }
    return keep(std::move(compound));
  }

  void refresh(Articulation& art) {
    if (!art.kinematics_stale) return;
    art.body->forwardKinematics(art.scratch_world_to_local, art.scratch_local_origin);
    art.kinematics_stale = false;
  }

  // After a state reset: link transforms and colliders current again.
  void updateKinematics(Articulation& art) {
    art.body->forwardKinematics(art.scratch_world_to_local, art.scratch_local_origin);
    art.body->updateCollisionObjectWorldTransforms(art.scratch_world_to_local,
                                                   art.scratch_local_origin);
    art.kinematics_stale = false;
  }
};

namespace {

// Principal-axes frame of a link's inertia (armature added about the joint
// axis), as Bullet needs a diagonal inertia: returns the diagonal and fills
// the rotation whose columns are the principal axes in joint-frame axes.
Vec3 principalInertia(const Mat3& inertia, Mat3& axes) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (inertia + inertia.transpose()));
  axes = eig.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  return eig.eigenvalues();
}

}  // namespace

PhysicsWorld::PhysicsWorld(const PhysicsSettings& settings)
    : settings_(settings), impl_(std::make_unique<Impl>()) {
  if (!(settings.dt > 0.0)) throw std::invalid_argument("physics dt must be > 0");
  if (settings.friction_directions != 1 && settings.friction_directions != 2)
    throw std::invalid_argument("friction_directions must be 1 or 2");
  if (settings.solver_threads < 1) throw std::invalid_argument("solver_threads must be >= 1");
  Impl& m = *impl_;
  m.config = std::make_unique<btDefaultCollisionConfiguration>();
  // Several contact points for a box resting on the ground plane (feet).
  m.config->setPlaneConvexMultipointIterations(3, 3);
  m.dispatcher = std::make_unique<btCollisionDispatcher>(m.config.get());
  if (settings.cull_ground_pairs) m.dispatcher->setNearCallback(&groundCullingNearCallback);
  m.broadphase = std::make_unique<btDbvtBroadphase>();
  m.solver = std::make_unique<ArticulationSolver>(!settings.bullet_solver);
  m.world = std::make_unique<TimedMultiBodyWorld>(m.dispatcher.get(), m.broadphase.get(),
                                                  m.solver.get(), m.config.get());
  m.world->getPairCache()->setOverlapFilterCallback(&m.filter);
  // The batches are formed and solved by the engine's own loop for any
  // number of threads (one: one after the other on the caller's thread), so
  // every thread count runs the same code; bullet_solver with one thread
  // keeps Bullet's own loop, to compare the two.
  m.all_solvers.push_back(m.solver.get());
  if (!settings.bullet_solver || settings.solver_threads > 1) {
    m.islands = std::make_unique<ParallelIslandSolver>(
        settings.solver_threads, [&m, own = !settings.bullet_solver] {
          auto solver = std::make_unique<ArticulationSolver>(own);
          m.all_solvers.push_back(solver.get());
          return solver;
        });
    m.world->islands = m.islands.get();
  }
  if (!settings.bullet_solver) {
    m.world->inertias = &m.inertias;
    for (ArticulationSolver* solver : m.all_solvers) {
      solver->setInertias(&m.inertias);
      solver->setWarmStart(static_cast<btScalar>(settings.contact_warm_start));
    }
  }
  // Restitution: the bouncier of the two materials decides (Bullet's default
  // multiplies them). A soft ball bounces off a hard foot, post or shin as it
  // bounces off anything hard, at its own restitution, while robots, the
  // carpet and the goal (all 0) meet each other inelastically. (The ball on
  // the carpet too bounces at 0.5: a foam ball dropped on turf does bounce.)
  // Process-wide in Bullet: set once, before any world steps.
  static std::once_flag restitution_rule;
  std::call_once(restitution_rule, [] {
    gCalculateCombinedRestitutionCallback = [](const btCollisionObject* a,
                                               const btCollisionObject* b) {
      return std::max(a->getRestitution(), b->getRestitution());
    };
  });
  m.world->setGravity(toBt(settings.gravity));
  btContactSolverInfo& info = m.world->getSolverInfo();
  info.m_numIterations = settings.solver_iterations;
  info.m_numNonContactInnerIterations = settings.joint_sweeps;
  // Two friction rows per contact: Bullet's multibody contacts take their
  // friction directions from the contact normal alone (btPlaneSpace1), so a
  // single row would resist slip along one fixed tangent only.
  if (settings.friction_directions == 2)
    info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  else
    info.m_solverMode &= ~SOLVER_USE_2_FRICTION_DIRECTIONS;
}

PhysicsWorld::~PhysicsWorld() {
  Impl& m = *impl_;
  for (auto& c : m.constraints) m.world->removeMultiBodyConstraint(c.get());
  for (auto& c : m.colliders) m.world->removeCollisionObject(c.get());
  for (auto& mb : m.multibodies) m.world->removeMultiBody(mb.get());
  for (auto& b : m.bodies) m.world->removeRigidBody(b.get());
  for (auto& s : m.statics) m.world->removeCollisionObject(s.get());
}

void PhysicsWorld::addGround(const Material& material) {
  Impl& m = *impl_;
  btCollisionShape* plane = m.keep(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0));
  auto obj = std::make_unique<btCollisionObject>();
  obj->setCollisionShape(plane);
  obj->setUserIndex(-1);
  obj->setUserIndex3(kGroundTag);
  applyMaterial(obj.get(), material);
  m.world->addCollisionObject(obj.get(), btBroadphaseProxy::StaticFilter,
                              btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
  m.statics.push_back(std::move(obj));
}

void PhysicsWorld::addStaticShape(const Shape& shape, const Material& material) {
  Impl& m = *impl_;
  auto obj = std::make_unique<btCollisionObject>();
  obj->setCollisionShape(m.keep(makePrimitive(shape)));
  obj->setWorldTransform(toBt(shape.pose));
  obj->setUserIndex(-1);
  applyMaterial(obj.get(), material);
  m.world->addCollisionObject(obj.get(), btBroadphaseProxy::StaticFilter,
                              btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
  m.statics.push_back(std::move(obj));
}

BodyId PhysicsWorld::addRigidBody(const Shape& shape, double mass, const Material& material,
                                  double linear_damping, double angular_damping, const Pose& pose) {
  if (!(mass > 0.0)) throw std::invalid_argument("rigid body mass must be > 0");
  Impl& m = *impl_;
  Shape centred = shape;
  centred.pose = Pose::Identity();
  btCollisionShape* s = m.keep(makePrimitive(centred));
  btVector3 inertia(0, 0, 0);
  s->calculateLocalInertia(static_cast<btScalar>(mass), inertia);
  m.motion_states.push_back(std::make_unique<btDefaultMotionState>(toBt(pose)));
  btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(mass),
                                                m.motion_states.back().get(), s, inertia);
  auto body = std::make_unique<btRigidBody>(info);
  body->setDamping(static_cast<btScalar>(linear_damping), static_cast<btScalar>(angular_damping));
  body->setActivationState(DISABLE_DEACTIVATION);  // a ball at rest must still react
  // Swept-sphere CCD so a fast shot cannot tunnel through a 20 mm net.
  const double r = shape.type == ShapeType::Sphere ? shape.radius : 0.05;
  body->setCcdMotionThreshold(static_cast<btScalar>(0.5 * r));
  body->setCcdSweptSphereRadius(static_cast<btScalar>(0.9 * r));
  body->setUserIndex(-1);
  body->setUserIndex2(static_cast<int>(m.bodies.size()));  // BodyId, reported in contacts
  body->setUserIndex3(kRigidBodyTag);
  applyMaterial(body.get(), material);
  m.world->addRigidBody(body.get());
  m.bodies.push_back(std::move(body));
  return static_cast<BodyId>(m.bodies.size() - 1);
}

ArticulationId PhysicsWorld::addArticulation(std::shared_ptr<const ArticulatedModel> model_ptr,
                                             const Pose& root_pose,
                                             std::span<const double> joint_positions,
                                             int collision_group) {
  Impl& m = *impl_;
  const ArticulatedModel& model = *model_ptr;
  validateModel(model);
  const int num_links = static_cast<int>(model.joints.size());

  Articulation art;
  art.model = model_ptr;
  art.bullet_in_joint.resize(model.links.size());
  art.joint_in_bullet.resize(model.links.size());
  art.servo.assign(model.joints.size(), -1);

  // Inertia per link, in principal axes (armature added about the joint axis).
  std::vector<Mat3> axes(model.links.size());
  std::vector<Vec3> diag(model.links.size());
  for (size_t i = 0; i < model.links.size(); ++i) {
    const Link& link = model.links[i];
    Mat3 inertia = link.inertia;
    if (i > 0) {
      const Joint& joint = model.joints[i - 1];
      if (joint.motor >= 0) {
        const Vec3 a = joint.axis.normalized();
        inertia += model.motors[static_cast<size_t>(joint.motor)].armature * a * a.transpose();
      }
    }
    diag[i] = principalInertia(inertia, axes[i]);
    Pose p = Pose::Identity();
    p.linear() = axes[i];
    p.translation() = link.com;
    art.bullet_in_joint[i] = p;
    art.joint_in_bullet[i] = p.inverse();
  }

  auto mb = std::make_unique<btMultiBody>(num_links, static_cast<btScalar>(model.links[0].mass),
                                          toBt(diag[0]), /*fixedBase=*/false, /*canSleep=*/false);
  for (int j = 0; j < num_links; ++j) {
    const Joint& joint = model.joints[static_cast<size_t>(j)];
    const size_t child = static_cast<size_t>(joint.child_link);
    const size_t parent = static_cast<size_t>(joint.parent_link);
    const Mat3 rot_parent_to_this = axes[child].transpose() * axes[parent];
    const Vec3 axis_in_this = axes[child].transpose() * joint.axis.normalized();
    const Vec3 parent_com_to_pivot =
        axes[parent].transpose() * (joint.origin - model.links[parent].com);
    const Vec3 pivot_to_com = axes[child].transpose() * model.links[child].com;
    mb->setupRevolute(j, static_cast<btScalar>(model.links[child].mass), toBt(diag[child]),
                      static_cast<int>(parent) - 1, toBt(Quat(rot_parent_to_this)),
                      toBt(axis_in_this), toBt(parent_com_to_pivot), toBt(pivot_to_com),
                      /*disableParentCollision=*/true);
  }
  mb->finalizeMultiDof();
  mb->setHasSelfCollision(false);
  mb->setLinearDamping(0);
  mb->setAngularDamping(0);
  mb->setUseGyroTerm(true);

  btMultiBody* raw = mb.get();
  raw->setUserIndex(static_cast<int>(m.multibodies.size()));  // its place in the world's list
  art.body = raw;
  m.multibodies.push_back(std::move(mb));  // owned before the world points to it
  m.inertias.resize(m.multibodies.size());
  m.world->addMultiBody(raw);

  // Colliders, one per link that has shapes; the user index is the group.
  for (size_t i = 0; i < model.links.size(); ++i) {
    const Link& link = model.links[i];
    if (link.shapes.empty()) continue;
    auto col = std::make_unique<btMultiBodyLinkCollider>(raw, static_cast<int>(i) - 1);
    col->setCollisionShape(m.linkShape(link, art.bullet_in_joint[i]));
    col->setUserIndex(collision_group);
    col->setUserIndex2(static_cast<int>(i));                       // link index in the model
    col->setUserIndex3(static_cast<int>(m.articulations.size()));  // articulation id
    applyMaterial(col.get(), link.material.value_or(model.material));
    m.world->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter,
                                btBroadphaseProxy::AllFilter);
    if (i == 0)
      raw->setBaseCollider(col.get());
    else
      raw->getLink(static_cast<int>(i) - 1).m_collider = col.get();
    m.colliders.push_back(std::move(col));
  }

  // Joint limits as unilateral constraints (rows only while at a limit) and
  // one servo per motorised joint.
  std::vector<int> column_coordinates;  // the implicit servos' (their responses solved together)
  for (int j = 0; j < num_links; ++j) {
    const Joint& joint = model.joints[static_cast<size_t>(j)];
    auto limit = std::make_unique<btMultiBodyJointLimitConstraint>(
        raw, j, static_cast<btScalar>(joint.lower), static_cast<btScalar>(joint.upper));
    m.world->addMultiBodyConstraint(limit.get());
    m.constraints.push_back(std::move(limit));
    if (joint.mimic_of >= 0) {
      // One motor drives both hinges through a rigid linkage: a gear
      // constraint q_mimic = multiplier * q_master (Bullet's rows enforce
      // qdot_A + ratio * qdot_B = 0), with position drift corrected.
      auto gear = std::make_unique<MimicConstraint>(
          raw, joint.mimic_of, j, settings_.bullet_solver ? nullptr : &m.inertias);
      gear->setGearRatio(static_cast<btScalar>(-1.0 / joint.mimic_multiplier));
      gear->setErp(0.2f);
      gear->setMaxAppliedImpulse(static_cast<btScalar>(1e3 * settings_.dt));
      m.world->addMultiBodyConstraint(gear.get());
      m.constraints.push_back(std::move(gear));
    }
    if (joint.motor >= 0) {
      // Lower bound of the inertia this joint moves: the armature plus its own
      // link about the joint axis (the rest of the chain only adds to it).
      const Link& link = model.links[static_cast<size_t>(joint.child_link)];
      const Motor& motor = model.motors[static_cast<size_t>(joint.motor)];
      const Vec3 a = joint.axis.normalized();
      const Mat3 about_joint =
          link.inertia +
          link.mass * (link.com.squaredNorm() * Mat3::Identity() - link.com * link.com.transpose());
      const double min_inertia = motor.armature + a.dot(about_joint * a);
      const bool implicit = motor.implicitAt(settings_.dt);
      const size_t s =
          m.servos.add(motor, joint.damping, joint.lower, joint.upper, min_inertia, implicit);
      art.servo[static_cast<size_t>(j)] = static_cast<int>(s);
      m.servo_body.push_back(raw);
      m.servo_link.push_back(j);
      if (implicit) {
        column_coordinates.push_back(6 + raw->getLink(j).m_dofOffset);
        auto row = std::make_unique<ServoConstraint>(
            raw, j, m.servos, s, settings_.bullet_solver ? nullptr : &m.inertias,
            settings_.envelope_in_solver);
        m.servo_rows.push_back(row.get());
        m.world->addMultiBodyConstraint(row.get());
        m.constraints.push_back(std::move(row));
      }
    }
  }
  m.inertias.setColumnCoordinates(static_cast<size_t>(raw->getUserIndex()),
                                  std::move(column_coordinates));
  m.q.resize(m.servos.size());
  m.qdot.resize(m.servos.size());

  m.articulations.push_back(std::move(art));
  const auto id = static_cast<ArticulationId>(m.articulations.size() - 1);
  resetArticulation(id, root_pose, joint_positions);
  for (int j = 0; j < num_links; ++j) {
    const double q0 = j < static_cast<int>(joint_positions.size())
                          ? joint_positions[static_cast<size_t>(j)]
                          : 0.0;
    const int s = m.articulations[id].servo[static_cast<size_t>(j)];
    if (s >= 0) m.servos.setTarget(static_cast<size_t>(s), q0, 0.0);
  }
  return id;
}

namespace {
// The servo of a commandable joint (-1: passive); throws for a mimic joint.
int commandedServo(const Articulation& art, int joint) {
  const Joint& j = art.model->joints.at(static_cast<size_t>(joint));
  if (j.mimic_of >= 0)
    throw std::invalid_argument("joint '" + j.name + "' follows '" +
                                art.model->joints[static_cast<size_t>(j.mimic_of)].name +
                                "' (one motor): command that joint");
  return art.servo[static_cast<size_t>(joint)];
}
}  // namespace

void PhysicsWorld::setJointTarget(ArticulationId a, int joint, double target_rad,
                                  double stiffness) {
  Impl& m = *impl_;
  const int s = commandedServo(m.articulations.at(a), joint);
  if (s >= 0) m.servos.setTarget(static_cast<size_t>(s), target_rad, stiffness);
}

void PhysicsWorld::setJointCommand(ArticulationId a, int joint, double target_rad, double velocity,
                                   double torque, double kp, double kd) {
  Impl& m = *impl_;
  const int s = commandedServo(m.articulations.at(a), joint);
  if (s >= 0) m.servos.setCommand(static_cast<size_t>(s), target_rad, velocity, torque, kp, kd);
}

void PhysicsWorld::resetArticulation(ArticulationId a, const Pose& root_pose,
                                     std::span<const double> joint_positions) {
  Impl& m = *impl_;
  Articulation& art = m.articulations.at(a);
  btMultiBody* mb = art.body;
  mb->setBaseWorldTransform(toBt(Pose(root_pose * art.bullet_in_joint[0])));
  mb->setBaseVel(btVector3(0, 0, 0));
  mb->setBaseOmega(btVector3(0, 0, 0));
  for (int j = 0; j < mb->getNumLinks(); ++j) {
    const double q0 = j < static_cast<int>(joint_positions.size())
                          ? joint_positions[static_cast<size_t>(j)]
                          : 0.0;
    mb->setJointPos(j, static_cast<btScalar>(q0));
    mb->setJointVel(j, 0);
    const int s = art.servo.empty() ? -1 : art.servo[static_cast<size_t>(j)];
    if (s >= 0) m.servos.resetHistory(static_cast<size_t>(s));
  }
  m.updateKinematics(art);
}

void PhysicsWorld::setRigidBodyState(BodyId b, const RigidBodyState& state) {
  btRigidBody* body = impl_->bodies.at(b).get();
  body->setWorldTransform(toBt(state.pose));
  body->getMotionState()->setWorldTransform(toBt(state.pose));
  body->setLinearVelocity(toBt(state.linear_velocity));
  body->setAngularVelocity(toBt(state.angular_velocity));
  body->clearForces();
}

void PhysicsWorld::setRootVelocity(ArticulationId a, const Vec3& linear, const Vec3& angular) {
  btMultiBody* mb = impl_->articulations.at(a).body;
  mb->setBaseVel(toBt(linear));
  mb->setBaseOmega(toBt(angular));
}

void PhysicsWorld::step() {
  Impl& m = *impl_;
  const auto t0 = timers_on_ ? Clock::now() : Clock::time_point{};
  m.world->times = timers_on_ ? &m.times : nullptr;

  // Stage 1: joint servos (gather, the batch's rows and passive torques, scatter).
  const size_t n = m.servos.size();
  for (size_t i = 0; i < n; ++i) {
    m.q[i] = m.servo_body[i]->getJointPos(m.servo_link[i]);
    m.qdot[i] = m.servo_body[i]->getJointVel(m.servo_link[i]);
  }
  m.servos.prepare(m.q, m.qdot, settings_.dt);
  for (size_t i = 0; i < n; ++i)
    m.servo_body[i]->addJointTorque(m.servo_link[i],
                                    static_cast<btScalar>(m.servos.appliedTorque(i)));
  for (ServoConstraint* row : m.servo_rows) row->startStep();
  if (timers_on_) m.times.servo_s += std::chrono::duration<double>(Clock::now() - t0).count();

  // Stage 2: Bullet (collision, dynamics, solve with the servo rows,
  // integrate); exactly one dt.
  const auto dt = static_cast<btScalar>(settings_.dt);
  for (ArticulationSolver* solver : m.all_solvers) solver->resetRowCounts();
  m.world->stepSimulation(dt, 0, dt);

  // Stage 3: the motor torques the solver applied.
  for (ServoConstraint* row : m.servo_rows) m.servos.setRowImpulse(row->servo(), row->impulse());
  for (Articulation& art : m.articulations) art.kinematics_stale = true;
  ++step_count_;
  if (timers_on_) {
    m.times.total_s += std::chrono::duration<double>(Clock::now() - t0).count();
    ++m.times.steps;
  }
}

void PhysicsWorld::checkInverseInertia(bool on) {
  impl_->inertias.check(on);
}

double PhysicsWorld::inverseInertiaMismatch() const {
  return impl_->inertias.mismatch();
}

PhysicsWorld::ContactRowCounts PhysicsWorld::lastStepContactRows() const {
  ContactRowCounts rows;
  for (const ArticulationSolver* solver : impl_->all_solvers) {
    rows.basis += solver->basisRows();
    rows.solved += solver->solvedRows();
    rows.between_articulations += solver->twoArticulationRows();
  }
  return rows;
}

int PhysicsWorld::lastStepSolverBatches() const {
  return impl_->islands ? impl_->islands->batchCount() : 0;
}

const StageTimes& PhysicsWorld::stageTimes() const {
  return impl_->times;
}
void PhysicsWorld::resetStageTimes() {
  impl_->times = StageTimes{};
}

Pose PhysicsWorld::linkPose(ArticulationId a, int link) const {
  Articulation& art = impl_->articulations.at(a);
  if (link < 0 || link >= static_cast<int>(art.model->links.size()))
    throw std::out_of_range("link index " + std::to_string(link) + " out of range");
  // Bullet keeps the root's and every collider's world transform current
  // (after each step and each state reset); only a link without collision
  // shapes needs forward kinematics, once per step.
  btTransform t;
  if (link == 0) {
    t = art.body->getBaseWorldTransform();
  } else if (const btMultiBodyLinkCollider* col = art.body->getLink(link - 1).m_collider) {
    t = col->getWorldTransform();
  } else {
    impl_->refresh(art);
    t = art.body->getLink(link - 1).m_cachedWorldTransform;
  }
  return fromBt(t) * art.joint_in_bullet[static_cast<size_t>(link)];
}

Vec3 PhysicsWorld::rootLinearVelocity(ArticulationId a) const {
  return fromBt(impl_->articulations.at(a).body->getBaseVel());
}
Vec3 PhysicsWorld::rootAngularVelocity(ArticulationId a) const {
  return fromBt(impl_->articulations.at(a).body->getBaseOmega());
}
namespace {
void checkJoint(const Articulation& art, int joint) {
  if (joint < 0 || joint >= static_cast<int>(art.model->joints.size()))
    throw std::out_of_range("joint index " + std::to_string(joint) + " out of range");
}
}  // namespace

double PhysicsWorld::jointPosition(ArticulationId a, int joint) const {
  const Articulation& art = impl_->articulations.at(a);
  checkJoint(art, joint);
  return art.body->getJointPos(joint);
}
double PhysicsWorld::jointVelocity(ArticulationId a, int joint) const {
  const Articulation& art = impl_->articulations.at(a);
  checkJoint(art, joint);
  return art.body->getJointVel(joint);
}
double PhysicsWorld::jointTorque(ArticulationId a, int joint) const {
  const int s = impl_->articulations.at(a).servo.at(static_cast<size_t>(joint));
  return s >= 0 ? impl_->servos.torque(static_cast<size_t>(s)) : 0.0;
}
double PhysicsWorld::jointMotorTorque(ArticulationId a, int joint) const {
  const int s = impl_->articulations.at(a).servo.at(static_cast<size_t>(joint));
  return s >= 0 ? impl_->servos.motorTorque(static_cast<size_t>(s)) : 0.0;
}
double PhysicsWorld::jointStiffness(ArticulationId a, int joint) const {
  const int s = impl_->articulations.at(a).servo.at(static_cast<size_t>(joint));
  return s >= 0 ? impl_->servos.stiffness(static_cast<size_t>(s)) : 0.0;
}
double PhysicsWorld::jointTarget(ArticulationId a, int joint) const {
  const int s = impl_->articulations.at(a).servo.at(static_cast<size_t>(joint));
  return s >= 0 ? impl_->servos.target(static_cast<size_t>(s)) : 0.0;
}

void PhysicsWorld::readJoints(ArticulationId a, std::span<double> position,
                              std::span<double> velocity, std::span<double> motor_torque,
                              std::span<double> target, std::span<double> stiffness) const {
  const Articulation& art = impl_->articulations.at(a);
  const size_t n = art.model->joints.size();
  for (const std::span<double>* out : {&position, &velocity, &motor_torque, &target, &stiffness})
    if (!out->empty() && out->size() != n)
      throw std::invalid_argument("readJoints: " + std::to_string(out->size()) + " entries for " +
                                  std::to_string(n) + " joints");
  const JointServoBatch& servos = impl_->servos;
  for (size_t j = 0; j < n; ++j) {
    const int link = static_cast<int>(j);
    if (!position.empty()) position[j] = art.body->getJointPos(link);
    if (!velocity.empty()) velocity[j] = art.body->getJointVel(link);
    const int s = art.servo[j];
    const auto si = static_cast<size_t>(s);
    if (!motor_torque.empty()) motor_torque[j] = s >= 0 ? servos.motorTorque(si) : 0.0;
    if (!target.empty()) target[j] = s >= 0 ? servos.target(si) : 0.0;
    if (!stiffness.empty()) stiffness[j] = s >= 0 ? servos.stiffness(si) : 0.0;
  }
}

RigidBodyState PhysicsWorld::rigidBodyState(BodyId b) const {
  const btRigidBody* body = impl_->bodies.at(b).get();
  return {fromBt(body->getWorldTransform()), fromBt(body->getLinearVelocity()),
          fromBt(body->getAngularVelocity())};
}

void PhysicsWorld::setActiveSolverThreads(int n) {
  if (impl_->islands) impl_->islands->setActiveThreads(n);
}

int PhysicsWorld::activeSolverThreads() const {
  return impl_->islands ? impl_->islands->activeThreads() : 1;
}

ContactCount PhysicsWorld::contactCount() const {
  btDispatcher* d = impl_->dispatcher.get();
  ContactCount c;
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    c.total += m->getNumContacts();
    const int g0 = m->getBody0()->getUserIndex(), g1 = m->getBody1()->getUserIndex();
    if (g0 >= 0 && g1 >= 0 && g0 != g1) c.between_articulations += m->getNumContacts();
  }
  return c;
}

void PhysicsWorld::linkContacts(std::vector<LinkContact>& out) const {
  out.clear();
  btDispatcher* d = impl_->dispatcher.get();
  for (int i = 0; i < d->getNumManifolds(); ++i) {
    const btPersistentManifold* m = d->getManifoldByIndexInternal(i);
    const btCollisionObject* bodies[2] = {m->getBody0(), m->getBody1()};
    const bool is_link[2] = {bodies[0]->getUserIndex() >= 0, bodies[1]->getUserIndex() >= 0};
    if (!is_link[0] && !is_link[1]) continue;
    for (int c = 0; c < m->getNumContacts(); ++c) {
      const btManifoldPoint& pt = m->getContactPoint(c);
      // m_normalWorldOnB points from B to A: the impulse pushes A along it.
      for (int side = 0; side < 2; ++side) {
        if (!is_link[side]) continue;
        LinkContact lc;
        lc.articulation = static_cast<ArticulationId>(bodies[side]->getUserIndex3());
        lc.link = bodies[side]->getUserIndex2();
        lc.position = fromBt(side == 0 ? pt.getPositionWorldOnA() : pt.getPositionWorldOnB());
        lc.normal = fromBt(side == 0 ? pt.m_normalWorldOnB : -pt.m_normalWorldOnB);
        lc.impulse = pt.getAppliedImpulse();
        lc.with_articulation = is_link[1 - side];
        const btCollisionObject* other = bodies[1 - side];
        if (lc.with_articulation) lc.other_articulation = other->getUserIndex3();
        if (other->getUserIndex3() == kRigidBodyTag) lc.other_body = other->getUserIndex2();
        out.push_back(lc);
      }
    }
  }
}

Vec3 PhysicsWorld::rootPointVelocity(ArticulationId a, const Vec3& world_point) const {
  const btMultiBody* mb = impl_->articulations.at(a).body;
  // The root's Bullet frame sits at its centre of mass.
  const Vec3 com = fromBt(mb->getBaseWorldTransform().getOrigin());
  return fromBt(mb->getBaseVel()) + fromBt(mb->getBaseOmega()).cross(world_point - com);
}

double PhysicsWorld::rayTestClosest(const Vec3& origin, const Vec3& direction, double max_distance,
                                    int exclude_group, Vec3* normal) const {
  struct Callback : btCollisionWorld::ClosestRayResultCallback {
    int exclude;
    Callback(const btVector3& from, const btVector3& to, int ex)
        : ClosestRayResultCallback(from, to), exclude(ex) {}
    bool needsCollision(btBroadphaseProxy* proxy) const override {
      const auto* o = static_cast<const btCollisionObject*>(proxy->m_clientObject);
      if (exclude >= 0 && o->getUserIndex() == exclude) return false;
      return ClosestRayResultCallback::needsCollision(proxy);
    }
  };
  const btVector3 from = toBt(origin);
  const btVector3 to = toBt(Vec3(origin + max_distance * direction.normalized()));
  Callback cb(from, to, exclude_group);
  // GJK cast: stops within 1 mm of the surface (the subsimplex cast is coarser).
  cb.m_flags |= btTriangleRaycastCallback::kF_UseGjkConvexCastRaytest;
  impl_->world->rayTest(from, to, cb);
  if (!cb.hasHit()) return std::numeric_limits<double>::infinity();
  if (normal) *normal = fromBt(cb.m_hitNormalWorld).normalized();
  return cb.m_closestHitFraction * max_distance;
}

void PhysicsWorld::appendState(std::vector<double>& out) const {
  auto push3 = [&](const btVector3& v) { out.insert(out.end(), {v.x(), v.y(), v.z()}); };
  auto pushT = [&](const btTransform& t) {
    push3(t.getOrigin());
    const btQuaternion q = t.getRotation();
    out.insert(out.end(), {q.x(), q.y(), q.z(), q.w()});
  };
  for (const Articulation& art : impl_->articulations) {
    const btMultiBody* mb = art.body;
    pushT(mb->getBaseWorldTransform());
    push3(mb->getBaseVel());
    push3(mb->getBaseOmega());
    for (int j = 0; j < mb->getNumLinks(); ++j) {
      out.push_back(mb->getJointPos(j));
      out.push_back(mb->getJointVel(j));
    }
  }
  for (const auto& body : impl_->bodies) {
    pushT(body->getWorldTransform());
    push3(body->getLinearVelocity());
    push3(body->getAngularVelocity());
  }
  impl_->servos.appendState(out);  // targets, stiffnesses and the motors' memory
}

}  // namespace simsoccer::engine

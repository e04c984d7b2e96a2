// The physics engine: a Bullet Featherstone world holding articulated robots
// (one btMultiBody each), free rigid bodies (the ball) and static geometry
// (ground, goals), stepped at a fixed time step.
//
// One step is a fixed sequence of stages (see step()): servo torques from
// the joint servo batch, then Bullet's collision detection, articulated-body
// dynamics, constraint solve and integration. No wall clock is read inside a
// step except by the optional stage timers, which only measure.
//
// Handles are plain indices (ArticulationId, BodyId) handed out in order of
// creation; nothing outside this component sees a Bullet pointer.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "simsoccer/engine/id.hpp"
#include "simsoccer/engine/joint_servo.hpp"
#include "simsoccer/engine/model.hpp"

namespace simsoccer::engine {

using ArticulationId = Id<struct ArticulationTag>;  // a robot's articulated body in the engine
using BodyId = Id<struct BodyTag>;                  // a free rigid body (the ball)

struct PhysicsSettings {
  double dt = 0.010;            // s, physics step (world::PhysicsConfig's default)
  int solver_iterations = 10;   // sequential-impulse iterations per step
  // Gauss-Seidel sweeps over the joint rows (servos, limits, gears) in each
  // iteration: cheap, one coordinate each; see world::PhysicsConfig.
  int joint_sweeps = 2;
  // The engine's solver starts each contact's rows from this share of its
  // point's impulses of the last step (0: from zero, as Bullet's; see
  // world::PhysicsConfig). Bullet's solver (bullet_solver) starts from zero.
  double contact_warm_start = 1.0;
  int friction_directions = 2;  // friction rows per contact (see world::PhysicsConfig)
  // Threads that solve the simulation islands (robots and what touches them)
  // side by side. The result is the same bit for bit for any number.
  int solver_threads = 1;
  // false (the default): the engine's solver (a foot's rows from its link's
  // spatial basis, a leaner iteration loop, the engine's batch loop with
  // each robot's forward dynamics in its batch). true: Bullet's own rows and
  // iterations, and with one thread Bullet's own island loop (for
  // comparisons). The two agree up to rounding.
  bool bullet_solver = false;
  // true (the default): the engine's solver bounds an implicit servo's torque
  // by its motor's torque-speed line at the joint speed it solves for
  // (JointServoBatch::Row::drive); false: by the bounds predicted before the
  // step, the only kind Bullet's solver can apply (to compare the two).
  // Bullet's solver (bullet_solver) always uses the predicted bounds.
  bool envelope_in_solver = true;
  // true: no narrowphase between the ground plane and a robot link clearly above it (the
  // same state bit for bit, less collision time); false: Bullet's for every link (to compare).
  bool cull_ground_pairs = true;
  Vec3 gravity{0.0, 0.0, -9.81};
};

// Wall time spent per stage, accumulated over steps (only when enabled).
struct StageTimes {
  double servo_s = 0.0;      // joint servo torques
  double collision_s = 0.0;  // broadphase + narrowphase
  // Forward dynamics; in the engine's batch loop only what precedes the
  // batches (each robot's own forward dynamics runs in its batch, as solver).
  double dynamics_s = 0.0;
  double solver_s = 0.0;     // contact, limit and implicit servo constraints
  double integrate_s = 0.0;  // position integration
  double total_s = 0.0;      // the whole step
  uint64_t steps = 0;
};

struct ContactCount {
  int total = 0;                  // contact points in all manifolds
  int between_articulations = 0;  // of which robot against robot
};

// One contact point as it acts on one link of an articulation.
struct LinkContact {
  ArticulationId articulation = 0;
  int link = 0;                    // link index in the articulation's model
  Vec3 position = Vec3::Zero();    // contact point on the link, world frame
  Vec3 normal = Vec3::Zero();      // unit direction of the normal impulse on the link
  double impulse = 0.0;            // N s applied along `normal` in the last step
  bool with_articulation = false;  // the other body is a link of another articulation
  int other_articulation = -1;     // ... that articulation's id
  int other_body = -1;             // the other body's BodyId if it is a free rigid body (the ball)
};

struct RigidBodyState {
  Pose pose = Pose::Identity();
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
};

class PhysicsWorld {
 public:
  explicit PhysicsWorld(const PhysicsSettings& settings);
  ~PhysicsWorld();
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  const PhysicsSettings& settings() const { return settings_; }
  // The solver threads given work, 1 .. settings().solver_threads (all at
  // first); the result is the same for any number. A pipelined run whose
  // periods have one CPU of their own uses one (sim/cores.hpp).
  void setActiveSolverThreads(int n);
  int activeSolverThreads() const;

  // --- building --------------------------------------------------------------
  // Infinite ground plane z = 0.
  void addGround(const Material& material);
  // A fixed collision primitive; shape.pose is in the world frame.
  void addStaticShape(const Shape& shape, const Material& material);
  // A free rigid body; shape.pose is ignored (the body frame is the shape's).
  BodyId addRigidBody(const Shape& shape, double mass, const Material& material,
                      double linear_damping, double angular_damping, const Pose& pose);
  // An articulated body; root_pose is the root link's joint frame in the world.
  // `collision_group` >= 0: links sharing a group never collide with each other
  // (self-collision off); different groups and everything else do collide.
  ArticulationId addArticulation(std::shared_ptr<const ArticulatedModel> model,
                                 const Pose& root_pose, std::span<const double> joint_positions,
                                 int collision_group);

  // --- commands ----------------------------------------------------------------
  // Servo target and stiffness of one joint. A mimic joint has no motor of
  // its own (a gear constraint ties it to its master): commanding it throws.
  void setJointTarget(ArticulationId a, int joint, double target_rad, double stiffness);
  // A command with its own servo gains (JointServoBatch::setCommand):
  // tau = kp (target - q) + kd (velocity - qdot) + torque, at full drive.
  void setJointCommand(ArticulationId a, int joint, double target_rad, double velocity,
                       double torque, double kp, double kd);
  // Teleports an articulation (zero velocities); for placement and tests.
  void resetArticulation(ArticulationId a, const Pose& root_pose,
                         std::span<const double> joint_positions);
  void setRigidBodyState(BodyId b, const RigidBodyState& state);
  // Root velocity in the world frame (for tests and scenario set-up).
  void setRootVelocity(ArticulationId a, const Vec3& linear, const Vec3& angular);

  // --- stepping ----------------------------------------------------------------
  void step();
  uint64_t stepCount() const { return step_count_; }
  void enableStageTimers(bool on) { timers_on_ = on; }
  const StageTimes& stageTimes() const;
  void resetStageTimes();
  // Constraint batches the last step's solver formed (solved side by side on
  // the solver threads; 0: Bullet's own loop, for a randomised row order).
  int lastStepSolverBatches() const;
  // Contact rows the engine built itself in the last step (all 0 with
  // bullet_solver): their responses from a link's spatial basis (three or
  // more points), solved one by one from the factorised inertia (fewer
  // points), and between two articulations (robot against robot, either kind).
  struct ContactRowCounts {
    long basis = 0, solved = 0, between_articulations = 0;
  };
  ContactRowCounts lastStepContactRows() const;
  // Checking (tests): every step's factorised joint-space inertia of each
  // articulation against Bullet's articulated-body pass, and its links' basis
  // Jacobians against Bullet's; the largest difference (of a column of M^-1,
  // of a Jacobian row) relative to its largest entry since checking
  // was turned on (negative: nothing checked, as with bullet_solver, which
  // factorises nothing).
  void checkInverseInertia(bool on);
  double inverseInertiaMismatch() const;

  // --- reading -----------------------------------------------------------------
  // Joint frame of a link in the world.
  Pose linkPose(ArticulationId a, int link) const;
  Vec3 rootLinearVelocity(ArticulationId a) const;
  Vec3 rootAngularVelocity(ArticulationId a) const;
  double jointPosition(ArticulationId a, int joint) const;
  double jointVelocity(ArticulationId a, int joint) const;
  // Torque the servo applied in the last step (motor + passive damping).
  double jointTorque(ArticulationId a, int joint) const;
  // The motor's part of it (what the motor current follows).
  double jointMotorTorque(ArticulationId a, int joint) const;
  double jointStiffness(ArticulationId a, int joint) const;
  double jointTarget(ArticulationId a, int joint) const;
  // The same of every joint at once, in joint order: each span empty (not read) or one entry
  // per joint. The sensors read the whole robot every step; one call instead of one per joint.
  void readJoints(ArticulationId a, std::span<double> position, std::span<double> velocity,
                  std::span<double> motor_torque, std::span<double> target,
                  std::span<double> stiffness) const;
  RigidBodyState rigidBodyState(BodyId b) const;
  // Contact points in the contact manifolds after the last step.
  ContactCount contactCount() const;
  // Every contact point touching a link of an articulation after the last
  // step, one entry per link side. Refills `out` (its capacity is reused).
  void linkContacts(std::vector<LinkContact>& out) const;
  // Velocity of a world point rigidly attached to an articulation's root.
  Vec3 rootPointVelocity(ArticulationId a, const Vec3& world_point) const;

  // Reference ray cast through Bullet (btCollisionWorld::rayTest), one ray:
  // distance to the nearest collider within max_distance, ignoring the links
  // of articulations in `exclude_group`; infinity if nothing. `normal`, if
  // given, receives Bullet's surface normal at the hit.
  double rayTestClosest(const Vec3& origin, const Vec3& direction, double max_distance,
                        int exclude_group, Vec3* normal = nullptr) const;

  // Appends the full dynamic state (every root pose and velocity, joint
  // positions and velocities, rigid bodies, servo targets and memory) as raw
  // values in creation order:
  // the canonical byte image that state hashes are computed over.
  void appendState(std::vector<double>& out) const;

 private:
  struct Impl;
  PhysicsSettings settings_;
  std::unique_ptr<Impl> impl_;
  uint64_t step_count_ = 0;
  bool timers_on_ = false;
};

}  // namespace simsoccer::engine

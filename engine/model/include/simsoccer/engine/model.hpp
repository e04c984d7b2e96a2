// Immutable description of an articulated body (a robot) and of collision
// primitives, independent of any file format. robots/ fills it from YAML;
// the PhysicsWorld turns it into Bullet objects.
//
// Frames: every link has a "joint frame" whose origin is the joint that moves
// the link (the root's is the torso origin) and whose axes are aligned with
// the root frame when all joint angles are zero (Aldebaran convention).
// Units: SI (m, kg, kg m^2, rad, N m, rad/s).
#pragma once

#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace simsoccer::engine {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;
using Pose = Eigen::Isometry3d;

enum class ShapeType { Sphere, Box, Capsule, Cylinder };

// A collision primitive. Capsules and cylinders run along the shape's local z
// axis; `length` is the full end-to-end length (a capsule's includes its caps).
struct Shape {
  ShapeType type = ShapeType::Sphere;
  double radius = 0.0;           // sphere, capsule, cylinder
  double length = 0.0;           // capsule, cylinder
  Vec3 extents = Vec3::Zero();   // box: full size along x, y, z
  Pose pose = Pose::Identity();  // in the owner's frame (link joint frame or world)
};

// Contact material. Two materials in contact: the product of their frictions
// (Bullet's rule) and the larger of their restitutions (PhysicsWorld's rule).
struct Material {
  double friction = 0.8;
  double rolling_friction = 0.0;   // m (torque = value * normal force)
  double spinning_friction = 0.0;  // m
  double restitution = 0.0;
};

struct Link {
  std::string name;
  double mass = 0.0;
  Vec3 com = Vec3::Zero();           // in the link's joint frame
  Mat3 inertia = Mat3::Zero();       // about the CoM, joint-frame axes
  std::vector<Shape> shapes;         // in the link's joint frame
  std::optional<Material> material;  // this link's own (a rubber sole); else the body's
};

// A position-controlled DC motor with gearbox, as seen at the joint.
struct Motor {
  std::string name;
  double stall_torque = 0.0;   // N m at the joint, stiffness 1
  double no_load_speed = 0.0;  // rad/s at the joint
  double armature = 0.0;       // reflected rotor inertia, kg m^2
  double kp = 0.0;             // N m/rad, servo proportional gain
  double kd = 0.0;             // N m s/rad, servo derivative gain
  // The servo's PD solved implicitly, by Bullet's constraint solver (stable
  // for any inertia, costs a solver row), or explicitly (a joint torque).
  bool implicit_servo = false;
  // An explicit servo's largest stable physics step, s: above it the servo
  // is solved implicitly (infinity: explicit at any step).
  double explicit_up_to = std::numeric_limits<double>::infinity();
  // Whether the servo is implicit in a world stepping dt seconds.
  bool implicitAt(double dt) const { return implicit_servo || dt > explicit_up_to; }
  // Electrical and thermal model (sensors: current, temperature).
  double gear_ratio = 1.0;
  double torque_constant = 0.0;        // N m/A at the motor shaft
  double resistance = 0.0;             // winding resistance, ohm
  double no_load_current = 0.0;        // A drawn while moving freely
  double thermal_resistance = 0.0;     // K/W, winding to ambient
  double thermal_time_constant = 0.0;  // s
};

// A revolute joint. Joint i moves link i + 1 (link 0 is the root), so the
// joint list is in tree order: a joint's parent link has a smaller index.
struct Joint {
  std::string name;
  int parent_link = 0;
  int child_link = 1;
  Vec3 axis = Vec3::UnitZ();   // unit, in the parent's joint frame at zero pose
  Vec3 origin = Vec3::Zero();  // joint position in the parent's joint frame
  double lower = 0.0;          // rad
  double upper = 0.0;          // rad
  int motor = -1;              // index into ArticulatedModel::motors, -1 = passive
  int mimic_of = -1;           // index of the joint whose command drives this one
  double mimic_multiplier = 1.0;
  double damping = 0.0;  // passive viscous damping, N m s/rad
};

struct ArticulatedModel {
  std::string name;
  std::vector<Link> links;    // links[0] is the root (floating base)
  std::vector<Joint> joints;  // joints[i].child_link == i + 1
  std::vector<Motor> motors;
  Material material;

  int linkIndex(const std::string& link_name) const;    // -1 if absent
  int jointIndex(const std::string& joint_name) const;  // -1 if absent
  double totalMass() const;
  // The whole body's centre of mass, given every link's joint frame (in any
  // one frame: the result is in it).
  Vec3 centreOfMass(std::span<const Pose> link_frames) const;
  // Joint-frame pose of every link relative to the root at the given joint
  // angles (forward kinematics on the model data alone, no physics).
  std::vector<Pose> linkFramesAt(const std::vector<double>& joint_positions) const;
  // Sets every mimic joint's angle from its master's (one angle per joint).
  void applyMimic(std::span<double> joint_positions) const;
};

}  // namespace simsoccer::engine

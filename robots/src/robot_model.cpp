#include "simsoccer/robots/robot_model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::robots {

using engine::ConfigNode;
using engine::Joint;
using engine::Link;
using engine::Mat3;
using engine::Vec3;

namespace {

Mat3 readInertia(const ConfigNode& n) {
  const auto v = n.numbers(6);  // ixx, iyy, izz, ixy, ixz, iyz
  Mat3 I;
  I << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
  const Vec3 d = eig.eigenvalues();
  if (d.minCoeff() <= 0.0) n.fail("inertia tensor must be positive definite");
  // Triangle inequality of principal moments (a physical rigid body).
  if (d[0] + d[1] < d[2] * (1.0 - 1e-6)) n.fail("inertia tensor violates the triangle inequality");
  return I;
}

// Moves the mass, inertia and shapes of `child` (attached rigidly at `origin`
// in parent's frame) into `parent`.
void mergeFixed(Link& parent, const Link& child, const Vec3& origin) {
  const double m = parent.mass + child.mass;
  const Vec3 child_com = origin + child.com;
  const Vec3 com = (parent.mass * parent.com + child.mass * child_com) / m;
  auto shifted = [](const Mat3& I, double mass, const Vec3& d) {
    return Mat3(I + mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  parent.inertia = shifted(parent.inertia, parent.mass, parent.com - com) +
                   shifted(child.inertia, child.mass, child_com - com);
  parent.mass = m;
  parent.com = com;
  for (engine::Shape s : child.shapes) {
    s.pose.pretranslate(origin);
    parent.shapes.push_back(s);
  }
}

struct RawJoint {
  ConfigNode node;
  std::string name, type, parent, child;
  Vec3 origin;
};

}  // namespace

const std::vector<double>& RobotModel::pose(const std::string& pose_name) const {
  auto it = poses.find(pose_name);
  if (it == poses.end())
    throw std::out_of_range("robot '" + name + "' has no pose '" + pose_name + "'");
  return it->second;
}

int RobotModel::actuatorIndex(const std::string& actuator_name) const {
  for (size_t i = 0; i < actuators.size(); ++i)
    if (actuators[i].name == actuator_name) return static_cast<int>(i);
  return -1;
}

const SensorFrame* RobotModel::sensor(const std::string& sensor_name) const {
  for (const SensorFrame& s : sensors)
    if (s.name == sensor_name) return &s;
  return nullptr;
}


double RobotModel::soleDepth(const std::vector<double>& q) const {
  const auto frames = body->linkFramesAt(q);
  double lowest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < body->links.size(); ++i) {
    for (const engine::Shape& s : body->links[i].shapes) {
      const Pose p = frames[i] * s.pose;
      const Vec3 c = p.translation();
      const Vec3 axis = p.linear().col(2);  // capsules and cylinders run along z
      switch (s.type) {
        case engine::ShapeType::Box:
          for (int k = 0; k < 8; ++k) {
            const Vec3 corner(((k & 1) ? 0.5 : -0.5) * s.extents.x(),
                              ((k & 2) ? 0.5 : -0.5) * s.extents.y(),
                              ((k & 4) ? 0.5 : -0.5) * s.extents.z());
            lowest = std::min(lowest, (p * corner).z());
          }
          break;
        case engine::ShapeType::Sphere:
          lowest = std::min(lowest, c.z() - s.radius);
          break;
        case engine::ShapeType::Capsule: {
          const double half = 0.5 * s.length - s.radius;
          lowest = std::min(lowest, c.z() - std::abs(axis.z()) * half - s.radius);
          break;
        }
        case engine::ShapeType::Cylinder: {
          const double rim = s.radius * std::sqrt(std::max(0.0, 1.0 - axis.z() * axis.z()));
          lowest = std::min(lowest, c.z() - std::abs(axis.z()) * 0.5 * s.length - rim);
          break;
        }
      }
    }
  }
  if (!std::isfinite(lowest))
    throw std::invalid_argument("robot '" + name + "' has no collision shapes to stand on");
  return -lowest;
}

RobotModel loadRobotModel(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"robot", "material", "encoder", "imu", "sonar", "thermal", "motors", "links",
                  "joints", "actuators", "absent_actuators", "hands", "sensors", "poses", "legs",
                  "fallen_torso_height"});
  RobotModel robot;
  robot.name = root["robot"].string();
  robot.source_file = file.string();
  auto body = std::make_shared<engine::ArticulatedModel>();
  body->name = robot.name;
  if (auto m = root.optional("material")) body->material = engine::readMaterial(*m, {});

  // Sensor hardware.
  SensorSpec& spec = robot.sensor_spec;
  if (auto n = root.optional("encoder")) {
    n->allowOnly({"bits"});
    spec.encoder_bits = (*n)["bits"].integer();
    if (spec.encoder_bits < 4 || spec.encoder_bits > 24) n->failKey("bits", "must be 4..24");
  }
  if (auto n = root.optional("imu")) {
    n->allowOnly({"gyro_range", "accel_range"});
    spec.gyro_range = (*n)["gyro_range"].positive();
    spec.accel_range = (*n)["accel_range"].positive();
  }
  if (auto n = root.optional("sonar")) {
    n->allowOnly(
        {"min_range", "max_range", "cone_angle", "no_echo_value", "max_echoes", "max_incidence"});
    spec.sonar_min_range = (*n)["min_range"].nonNegative();
    spec.sonar_max_range = (*n)["max_range"].positive();
    if (spec.sonar_max_range <= spec.sonar_min_range)
      n->failKey("max_range", "must exceed min_range");
    spec.sonar_cone_angle = (*n)["cone_angle"].positive();
    if (spec.sonar_cone_angle >= M_PI) n->failKey("cone_angle", "must be below pi");
    spec.sonar_no_echo_value = (*n)["no_echo_value"].positive();
    spec.sonar_max_echoes = (*n)["max_echoes"].integer();
    if (spec.sonar_max_echoes < 1 || spec.sonar_max_echoes > 10)
      n->failKey("max_echoes", "must be 1..10 (the Nao reports up to 10)");
    spec.sonar_max_incidence = (*n)["max_incidence"].positive();
    if (spec.sonar_max_incidence > M_PI / 2) n->failKey("max_incidence", "must be at most pi/2");
  }
  if (auto n = root.optional("thermal")) {
    n->allowOnly({"ambient", "hot", "very_hot", "critical"});
    spec.ambient_temperature = (*n)["ambient"].number();
    spec.temperature_hot = (*n)["hot"].number();
    spec.temperature_very_hot = (*n)["very_hot"].number();
    spec.temperature_critical = (*n)["critical"].number();
    if (!(spec.ambient_temperature < spec.temperature_hot &&
          spec.temperature_hot < spec.temperature_very_hot &&
          spec.temperature_very_hot < spec.temperature_critical))
      n->fail("expected ambient < hot < very_hot < critical");
  }

  // Motors.
  std::map<std::string, double> motor_damping;
  for (const auto& [name, n] : root["motors"].entries()) {
    n.allowOnly({"motor_type", "gear_ratio", "stall_torque", "no_load_speed", "armature", "kp",
                 "kd", "damping", "torque_constant", "resistance", "no_load_current",
                 "thermal_resistance", "thermal_time_constant", "servo", "explicit_up_to"});
    engine::Motor m;
    m.name = name;
    m.stall_torque = n["stall_torque"].positive();
    m.no_load_speed = n["no_load_speed"].positive();
    m.armature = n["armature"].nonNegative();
    m.kp = n["kp"].nonNegative();
    m.kd = n["kd"].nonNegative();
    if (n.has("servo")) {
      const std::string servo = n["servo"].string();
      if (servo != "implicit" && servo != "explicit")
        n["servo"].fail("must be implicit or explicit, not '" + servo + "'");
      m.implicit_servo = servo == "implicit";
    }
    if (n.has("explicit_up_to")) {
      if (m.implicit_servo) n["explicit_up_to"].fail("only for an explicit servo");
      m.explicit_up_to = n["explicit_up_to"].positive();
    }
    m.gear_ratio = n["gear_ratio"].positive();
    m.torque_constant = n["torque_constant"].positive();
    m.resistance = n["resistance"].positive();
    m.no_load_current = n["no_load_current"].nonNegative();
    m.thermal_resistance = n["thermal_resistance"].positive();
    m.thermal_time_constant = n["thermal_time_constant"].positive();
    motor_damping[name] = n.has("damping") ? n["damping"].nonNegative() : 0.0;
    body->motors.push_back(m);
  }
  auto motorIndex = [&](const ConfigNode& n) {
    const std::string name = n.string();
    for (size_t i = 0; i < body->motors.size(); ++i)
      if (body->motors[i].name == name) return static_cast<int>(i);
    n.fail("unknown motor '" + name + "' (not in 'motors')");
  };

  // Links, by name.
  std::map<std::string, Link> links;
  std::vector<std::string> link_order;
  for (const ConfigNode& n : root["links"].items()) {
    n.allowOnly({"name", "mass", "com", "inertia", "collision", "material"});
    Link l;
    l.name = n["name"].string();
    if (links.count(l.name)) n["name"].fail("duplicate link name '" + l.name + "'");
    l.mass = n["mass"].positive();
    l.com = n["com"].vec3();
    l.inertia = readInertia(n["inertia"]);
    if (auto c = n.optional("collision"))
      for (const ConfigNode& s : c->items()) l.shapes.push_back(engine::readShape(s));
    if (auto m = n.optional("material")) l.material = engine::readMaterial(*m, body->material);
    links[l.name] = l;
    link_order.push_back(l.name);
  }

  // Joints: fixed joints are merged into their parent link first.
  std::vector<RawJoint> raw;
  std::set<std::string> joint_names;
  for (const ConfigNode& n : root["joints"].items()) {
    n.allowOnly({"name", "type", "parent", "child", "origin", "axis", "limits", "motor", "mimic",
                 "damping"});
    RawJoint j{n,
               n["name"].string(),
               n.has("type") ? n["type"].string() : "revolute",
               n["parent"].string(),
               n["child"].string(),
               n["origin"].vec3()};
    if (!joint_names.insert(j.name).second) n["name"].fail("duplicate joint name '" + j.name + "'");
    if (j.type != "revolute" && j.type != "fixed")
      n["type"].fail("unknown joint type '" + j.type + "' (revolute or fixed)");
    if (!links.count(j.parent)) n["parent"].fail("unknown link '" + j.parent + "'");
    if (!links.count(j.child)) n["child"].fail("unknown link '" + j.child + "'");
    if (j.child == j.parent) n["child"].fail("a joint cannot attach a link to itself");
    for (const RawJoint& other : raw)
      if (other.child == j.child)
        n["child"].fail("link '" + j.child + "' is already attached by joint '" + other.name + "'");
    if (j.type == "fixed") {
      for (const char* key : {"axis", "limits", "motor", "mimic", "damping"})
        if (n.has(key)) n.failKey(key, "a fixed joint has no '" + std::string(key) + "'");
    } else if (n.has("mimic") && n.has("motor")) {
      n.failKey("motor", "a mimic joint is driven by its master's motor: remove 'motor'");
    } else if (n.has("damping") && !n.has("motor")) {
      n.failKey("damping", "passive damping is applied by a joint's motor: this joint has none");
    }
    raw.push_back(j);
  }
  std::map<std::string, std::string> merged_into;  // fixed child -> parent it joined
  std::map<std::string, Vec3> merged_offset;
  auto resolve = [&](std::string link, Vec3& offset) {
    offset = Vec3::Zero();
    while (merged_into.count(link)) {
      offset += merged_offset[link];
      link = merged_into[link];
    }
    return link;
  };
  for (const RawJoint& j : raw) {
    if (j.type != "fixed") continue;
    Vec3 off;
    const std::string parent = resolve(j.parent, off);
    // One collider per link, so one material: a fixed link joins its parent's.
    if (links[j.child].material)
      j.node["child"].fail("link '" + j.child + "' has a material of its own but is fixed to '" +
                           parent + "' (one material per moving link)");
    mergeFixed(links[parent], links[j.child], off + j.origin);
    merged_into[j.child] = parent;
    merged_offset[j.child] = off + j.origin;
  }

  std::set<std::string> children;
  for (const RawJoint& j : raw) children.insert(j.child);
  std::vector<std::string> roots;
  for (const std::string& name : link_order)
    if (!children.count(name)) roots.push_back(name);
  if (roots.size() != 1)
    root["links"].fail("expected exactly one root link (a link that is no joint's child), found " +
                       std::to_string(roots.size()));
  body->links.push_back(links[roots[0]]);
  for (const RawJoint& j : raw) {
    if (j.type == "fixed") continue;
    Vec3 off;
    const std::string parent = resolve(j.parent, off);
    Joint joint;
    joint.name = j.name;
    joint.parent_link = body->linkIndex(parent);
    if (joint.parent_link < 0)
      j.node["parent"].fail("link '" + j.parent +
                            "' must be attached by an earlier joint (tree order)");
    joint.child_link = static_cast<int>(body->links.size());
    joint.origin = off + j.origin;
    joint.axis = j.node["axis"].vec3();
    if (std::abs(joint.axis.norm() - 1.0) > 1e-3) j.node["axis"].fail("must be a unit vector");
    joint.axis.normalize();
    const auto lim = j.node["limits"].numbers(2);
    if (!(lim[0] < lim[1])) j.node["limits"].fail("lower limit must be below upper limit");
    joint.lower = lim[0];
    joint.upper = lim[1];
    if (auto m = j.node.optional("motor")) {
      joint.motor = motorIndex(*m);
      joint.damping = motor_damping[m->string()];
    }
    if (auto d = j.node.optional("damping")) joint.damping = d->nonNegative();
    body->links.push_back(links[j.child]);
    body->joints.push_back(joint);
  }
  // Mimic joints (after all joints exist, so the master may come later).
  for (const RawJoint& j : raw) {
    auto mimic = j.node.optional("mimic");
    if (!mimic) continue;
    if (j.type == "fixed") mimic->fail("a fixed joint cannot mimic");
    mimic->allowOnly({"joint", "multiplier"});
    const int self = body->jointIndex(j.name);
    const int master = body->jointIndex((*mimic)["joint"].string());
    if (master < 0) (*mimic)["joint"].fail("unknown joint '" + (*mimic)["joint"].string() + "'");
    if (master == self) (*mimic)["joint"].fail("a joint cannot mimic itself");
    if (body->joints[static_cast<size_t>(master)].motor < 0)
      (*mimic)["joint"].fail("the master joint '" + (*mimic)["joint"].string() + "' has no motor");
    for (const RawJoint& other : raw)
      if (other.name == (*mimic)["joint"].string() && other.node.has("mimic"))
        (*mimic)["joint"].fail("the master joint mimics another joint itself");
    if (mimic->number("multiplier", 1.0) == 0.0) mimic->failKey("multiplier", "must not be 0");
    body->joints[static_cast<size_t>(self)].mimic_of = master;
    body->joints[static_cast<size_t>(self)].mimic_multiplier = mimic->number("multiplier", 1.0);
  }

  // Hands.
  if (auto hands = root.optional("hands")) {
    for (const ConfigNode& n : hands->items()) {
      n.allowOnly({"name", "link", "limits", "motor", "speed"});
      Hand h;
      h.name = n["name"].string();
      Vec3 off;
      h.link = body->linkIndex(resolve(n["link"].string(), off));
      if (h.link < 0) n["link"].fail("unknown link '" + n["link"].string() + "'");
      const auto lim = n["limits"].numbers(2);
      if (!(lim[0] < lim[1])) n["limits"].fail("lower limit must be below upper limit");
      h.lower = lim[0];
      h.upper = lim[1];
      h.motor = motorIndex(n["motor"]);
      h.speed = n["speed"].positive();
      robot.hands.push_back(h);
    }
  }

  // Actuators (the command order).
  std::set<std::string> absent;
  if (auto a = root.optional("absent_actuators"))
    for (const ConfigNode& n : a->items()) absent.insert(n.string());
  std::set<std::string> seen;
  for (const ConfigNode& n : root["actuators"].items()) {
    Actuator a;
    a.name = n.string();
    if (!seen.insert(a.name).second) n.fail("duplicate actuator '" + a.name + "'");
    const int joint = body->jointIndex(a.name);
    int hand = -1;
    for (size_t i = 0; i < robot.hands.size(); ++i)
      if (robot.hands[i].name == a.name) hand = static_cast<int>(i);
    if (joint >= 0) {
      if (body->joints[static_cast<size_t>(joint)].motor < 0)
        n.fail("joint '" + a.name + "' has no motor and cannot be an actuator");
      a.kind = Actuator::Kind::Joint;
      a.index = joint;
    } else if (hand >= 0) {
      a.kind = Actuator::Kind::Hand;
      a.index = hand;
    } else if (absent.count(a.name)) {
      a.kind = Actuator::Kind::Absent;
    } else {
      n.fail("unknown actuator '" + a.name + "' (not a joint, a hand or in absent_actuators)");
    }
    robot.actuators.push_back(a);
  }

  // Sensor frames.
  if (auto sensors = root.optional("sensors")) {
    for (const ConfigNode& n : sensors->items()) {
      n.allowOnly({"name", "type", "link", "position", "rpy", "fov"});
      SensorFrame s;
      s.name = n["name"].string();
      s.type = n["type"].string();
      static const char* kTypes[] = {"accelerometer", "gyroscope", "camera", "sonar",
                                     "fsr",           "bumper",    "touch"};
      if (std::find(std::begin(kTypes), std::end(kTypes), s.type) == std::end(kTypes))
        n["type"].fail("unknown sensor type '" + s.type +
                       "' (accelerometer, gyroscope, camera, sonar, fsr, bumper, touch)");
      // A camera's field of view: [horizontal, vertical] in rad, each in (0, pi).
      if (s.type == "camera") {
        const ConfigNode fov = n["fov"];
        const std::vector<double> v = fov.numbers();
        if (v.size() != 2) fov.fail("expected [horizontal, vertical] in rad");
        for (double a : v)
          if (!(a > 0.0 && a < std::numbers::pi)) fov.fail("each angle must be in (0, pi) rad");
        s.horizontal_fov = v[0];
        s.vertical_fov = v[1];
      } else if (n.has("fov")) {
        n["fov"].fail("only a camera has a field of view");
      }
      Vec3 off;
      s.link = body->linkIndex(resolve(n["link"].string(), off));
      if (s.link < 0) n["link"].fail("unknown link '" + n["link"].string() + "'");
      s.pose = engine::readPose(n);
      s.pose.pretranslate(off);
      if (s.type == "camera") robot.camera_sensors.push_back(robot.sensors.size());
      robot.sensors.push_back(s);
    }
  }

  // Named poses, validated against the joint limits.
  if (auto poses = root.optional("poses")) {
    for (const auto& [pose_name, n] : poses->entries()) {
      std::vector<double> q(body->joints.size(), 0.0);
      if (!n.raw().IsMap()) n.fail("expected a mapping of joint names to angles");
      for (const auto& [joint_name, v] : n.entries()) {
        const int j = body->jointIndex(joint_name);
        if (j < 0) v.fail("unknown joint '" + joint_name + "'");
        q[static_cast<size_t>(j)] = v.number();
      }
      body->applyMimic(q);
      for (size_t j = 0; j < q.size(); ++j) {
        const Joint& joint = body->joints[j];
        if (q[j] < joint.lower - 1e-9 || q[j] > joint.upper + 1e-9)
          n.failKey(joint.name,
                    "angle " + engine::formatNumber(q[j]) + " is outside the joint limits");
      }
      robot.poses[pose_name] = q;
    }
  }
  // The legs: each foot link's chain of joints up to the trunk.
  if (auto legs = root.optional("legs")) {
    legs->allowOnly({"left", "right"});
    for (size_t side = 0; side < 2; ++side) {
      const ConfigNode n = (*legs)[side == 0 ? "left" : "right"];
      LegChain& chain = robot.legs[side];
      chain.foot_link = body->linkIndex(n.string());
      if (chain.foot_link <= 0) n.fail("unknown foot link '" + n.string() + "' (or the trunk)");
      // joints[i] moves link i + 1: walk up from the foot to the root.
      for (int link = chain.foot_link; link > 0;) {
        const int joint = link - 1;
        chain.joints.insert(chain.joints.begin(), joint);
        link = body->joints[static_cast<size_t>(joint)].parent_link;
      }
    }
    if (robot.legs[0].foot_link == robot.legs[1].foot_link)
      (*legs)["right"].fail("the right foot is the left foot's link");
  }
  robot.body = std::move(body);
  // Below the standing torso: a robot in its stand pose must count as standing.
  const ConfigNode fallen = root["fallen_torso_height"];
  robot.fallen_torso_height = fallen.positive();
  if (const auto stand = robot.poses.find("stand"); stand != robot.poses.end() && robot.hasLegs()) {
    const double standing = robot.soleDepth(stand->second);
    if (robot.fallen_torso_height >= standing)
      fallen.fail("must be below the torso's height in the stand pose (" +
                  engine::formatNumber(std::round(standing * 1000.0) / 1000.0) + " m)");
  }
  return robot;
}

}  // namespace simsoccer::robots

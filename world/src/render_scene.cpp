#include "simsoccer/world/render_scene.hpp"

#include <cmath>

namespace simsoccer::world {
namespace {

using engine::DrawItem;
using engine::Primitive;
using engine::Vec3;

Eigen::Matrix4f toMatrix(const engine::Pose& pose, const Vec3& scale) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = pose.linear() * scale.asDiagonal();
  m.block<3, 1>(0, 3) = pose.translation();
  return m.cast<float>();
}

void add(std::vector<DrawItem>& items, Primitive shape, const engine::Pose& pose, const Vec3& scale,
         const Eigen::Vector3f& colour, bool pattern = false) {
  items.push_back({shape, toMatrix(pose, scale), colour, pattern, false, 0.0f});
}

// Paint on the ground: a quad in the plane z = 0 (the renderer draws these in order).
void addGround(std::vector<DrawItem>& items, const Vec3& centre, double yaw, double length,
               double width, const Eigen::Vector3f& colour) {
  engine::Pose p = engine::Pose::Identity();
  p.rotate(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  p.translation() = centre;
  items.push_back(
      {Primitive::Quad, toMatrix(p, Vec3(length, width, 1.0)), colour, false, true, 0.0f});
}

// A collision primitive as render instances (a capsule: cylinder + 2 spheres).
void addShape(std::vector<DrawItem>& items, const engine::Shape& s, const engine::Pose& world_pose,
              const Eigen::Vector3f& colour) {
  const engine::Pose p = world_pose * s.pose;
  switch (s.type) {
    case engine::ShapeType::Box:
      add(items, Primitive::Box, p, s.extents, colour);
      break;
    case engine::ShapeType::Sphere:
      add(items, Primitive::CoarseSphere, p, Vec3::Constant(s.radius), colour);
      break;
    case engine::ShapeType::Cylinder:
      add(items, Primitive::Cylinder, p, Vec3(s.radius, s.radius, s.length), colour);
      break;
    case engine::ShapeType::Capsule: {
      const double half = 0.5 * s.length - s.radius;  // between the cap centres, halved
      add(items, Primitive::Capsule, p, Vec3::Constant(s.radius), colour);
      items.back().stretch = static_cast<float>(half / s.radius);
      break;
    }
  }
}

// A painted line from a to b, its ends squared off half a width beyond them.
void addLine(std::vector<DrawItem>& items, const fields::Vec2& a, const fields::Vec2& b,
             double width, const Eigen::Vector3f& colour) {
  const fields::Vec2 d = b - a;
  addGround(items, Vec3(0.5 * (a.x() + b.x()), 0.5 * (a.y() + b.y()), 0.0),
            std::atan2(d.y(), d.x()), d.norm() + (d.norm() > 0 ? width : 0), width, colour);
}

}  // namespace

void buildRenderScene(const World& world, std::vector<DrawItem>& items, const SceneColours& c) {
  const auto& f = world.field();
  // The ground in painter's order (the renderer draws it first, later paint
  // over earlier, no depth test): the floor as a 10 m ring around the carpet
  // (not a quad under it, which would be shaded twice), the carpet, the lines.
  const double carpet_length = f.length + 2 * f.border, carpet_width = f.width + 2 * f.border;
  const double ring = 10.0;
  for (int side : {-1, 1}) {
    addGround(items, Vec3(side * 0.5 * (carpet_length + ring), 0, 0), 0.0, ring,
              carpet_width + 2 * ring, c.floor);
    addGround(items, Vec3(0, side * 0.5 * (carpet_width + ring), 0), 0.0, carpet_length, ring,
              c.floor);
  }
  addGround(items, Vec3::Zero(), 0.0, carpet_length, carpet_width, c.carpet);
  for (const auto& l : f.lines) addLine(items, l.a, l.b, f.line_width, c.line);
  for (const auto& circle : f.circles) {
    const int segments = 24;  // few triangles: llvmpipe pays per triangle
    for (int i = 0; i < segments; ++i) {
      const double a0 = 2 * M_PI * i / segments, a1 = 2 * M_PI * (i + 1) / segments;
      addLine(items, circle.centre + circle.radius * fields::Vec2(std::cos(a0), std::sin(a0)),
              circle.centre + circle.radius * fields::Vec2(std::cos(a1), std::sin(a1)),
              f.line_width, c.line);
    }
  }
  for (const auto& m : f.marks) {  // crosses
    const double h = 0.5 * f.penalty_mark_size;
    addLine(items, m - fields::Vec2(h, 0), m + fields::Vec2(h, 0), f.line_width, c.line);
    addLine(items, m - fields::Vec2(0, h), m + fields::Vec2(0, h), f.line_width, c.line);
  }
  // Robots from their collision primitives; the torso in the jersey colour.
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& info = world.robot(r);
    const auto& links = info.model->body->links;
    const Eigen::Vector3f jersey =
        c.jerseys.empty() ? c.robot : c.jerseys[static_cast<size_t>(info.team) % c.jerseys.size()];
    for (size_t l = 0; l < links.size(); ++l) {
      if (links[l].shapes.empty()) continue;
      const engine::Pose lp = world.linkPose(r, static_cast<int>(l));
      for (const auto& s : links[l].shapes) addShape(items, s, lp, l == 0 ? jersey : c.robot);
    }
    // LEDs (a Nao's, set through LoLA): the chest button (nao.md 5.4: 49.9,
    // 1.6, 55.2 mm in the torso frame) and the eyes on the face, beside the
    // top camera, a little proud of the shells so the spectator sees them.
    if (r < c.leds.size() && c.leds[r]) {
      const engine::Pose torso = world.linkPose(r, 0);
      engine::Pose at = torso;
      at.translation() = torso * Vec3(0.058, 0.0016, 0.0552);
      add(items, Primitive::Sphere, at, Vec3::Constant(0.014), c.leds[r]->chest, false);
      if (const robots::SensorFrame* cam = info.model->sensor("CameraTop")) {
        const engine::Pose head = world.linkPose(r, cam->link);
        for (int side : {1, -1}) {
          at = head;
          at.translation() = head * Vec3(0.056, side * 0.034, 0.071);
          add(items, Primitive::Sphere, at, Vec3::Constant(0.010),
              side > 0 ? c.leds[r]->left_eye : c.leds[r]->right_eye, false);
        }
      }
    }
  }
  // The ball.
  const engine::RigidBodyState ball = world.ballState();
  add(items, Primitive::Sphere, ball.pose, Vec3::Constant(f.ball.radius), c.ball, true);
  // Goals: posts and crossbar white, net grey.
  for (int side : {-1, 1}) {
    const auto shapes = f.goalShapes(side);
    for (size_t i = 0; i < shapes.size(); ++i)
      addShape(items, shapes[i], engine::Pose::Identity(), i < 3 ? c.goal : c.net);
  }
}

engine::RenderView robotCameraView(const World& world, RobotId r, const std::string& camera,
                                   int width, int height) {
  const auto& info = world.robot(r);
  const robots::SensorFrame* s = info.model->sensor(camera);
  if (!s || s->type != "camera")
    throw std::invalid_argument("robot model " + info.model->name + " has no camera " + camera);
  return robotCameraView(world, r, *s, width, height);
}

engine::RenderView robotCameraView(const World& world, RobotId r,
                                   const robots::SensorFrame& camera, int width, int height) {
  return engine::pinholeView(robotCameraPose(world, r, camera), width, height,
                             camera.horizontal_fov, camera.vertical_fov);
}

engine::Pose robotCameraPose(const World& world, RobotId r, const robots::SensorFrame& camera) {
  return world.linkPose(r, camera.link) * camera.pose;
}

engine::Pose lookAtPose(const Vec3& position, const Vec3& target) {
  const Vec3 x = (target - position).normalized();
  Vec3 y = Vec3::UnitZ().cross(x);
  if (y.norm() < 1e-6) y = Vec3::UnitY();  // looking straight down or up
  y.normalize();
  engine::Pose p = engine::Pose::Identity();
  p.linear().col(0) = x;
  p.linear().col(1) = y;
  p.linear().col(2) = x.cross(y);
  p.translation() = position;
  return p;
}

}  // namespace simsoccer::world

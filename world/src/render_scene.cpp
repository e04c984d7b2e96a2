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
  items.push_back({shape, toMatrix(pose, scale), colour, pattern});
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
      add(items, Primitive::Cylinder, p, Vec3(s.radius, s.radius, 2 * half), colour);
      for (double z : {-half, half}) {
        engine::Pose cap = p;
        cap.translation() = p * Vec3(0, 0, z);
        add(items, Primitive::CoarseSphere, cap, Vec3::Constant(s.radius), colour);
      }
      break;
    }
  }
}

// A painted line: a quad just above the carpet.
void addLine(std::vector<DrawItem>& items, const fields::Vec2& a, const fields::Vec2& b,
             double width, const Eigen::Vector3f& colour) {
  const fields::Vec2 d = b - a;
  engine::Pose p = engine::Pose::Identity();
  p.rotate(Eigen::AngleAxisd(std::atan2(d.y(), d.x()), Vec3::UnitZ()));
  p.translation() = Vec3(0.5 * (a.x() + b.x()), 0.5 * (a.y() + b.y()), 0.001);
  add(items, Primitive::Quad, p, Vec3(d.norm() + (d.norm() > 0 ? width : 0), width, 1.0), colour);
}

}  // namespace

void buildRenderScene(const World& world, std::vector<DrawItem>& items, const SceneColours& c) {
  // Nearest things first, the ground last: the renderer keeps this order, and
  // ground hidden behind robots then fails the early depth test.
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
  }
  const auto& f = world.field();
  // The lines, then the carpet, then the floor around it.
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
  // The ball.
  const engine::RigidBodyState ball = world.ballState();
  add(items, Primitive::Sphere, ball.pose, Vec3::Constant(f.ball.radius), c.ball, true);
  // Goals: posts and crossbar white, net grey.
  for (int side : {-1, 1}) {
    const auto shapes = f.goalShapes(side);
    for (size_t i = 0; i < shapes.size(); ++i)
      addShape(items, shapes[i], engine::Pose::Identity(), i < 3 ? c.goal : c.net);
  }
  // The carpet (its surface at z = 0) and the floor around it, 1 cm lower.
  engine::Pose p = engine::Pose::Identity();
  add(items, Primitive::Quad, p, Vec3(f.length + 2 * f.border, f.width + 2 * f.border, 1.0),
      c.carpet);
  p.translation() = Vec3(0, 0, -0.01);
  add(items, Primitive::Quad, p,
      Vec3(f.length + 2 * f.border + 20, f.width + 2 * f.border + 20, 1.0), c.floor);
}

engine::RenderView robotCameraView(const World& world, RobotId r, const std::string& camera,
                                   int width, int height, double horizontal_fov,
                                   double vertical_fov) {
  const auto& info = world.robot(r);
  const robots::SensorFrame* s = info.model->sensor(camera);
  if (!s || s->type != "camera")
    throw std::invalid_argument("robot model " + info.model->name + " has no camera " + camera);
  return engine::pinholeView(world.linkPose(r, s->link) * s->pose, width, height, horizontal_fov,
                             vertical_fov);
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

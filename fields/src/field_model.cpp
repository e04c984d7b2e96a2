#include "simsoccer/fields/field_model.hpp"

#include <algorithm>
#include <cmath>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::fields {

using engine::ConfigNode;
using engine::Shape;
using engine::ShapeType;
using engine::Vec3;

namespace {

void buildMarkings(FieldModel& f) {
  const double hx = f.halfLength(), hy = f.halfWidth();
  auto line = [&](double x0, double y0, double x1, double y1) {
    f.lines.push_back({Vec2(x0, y0), Vec2(x1, y1)});
  };
  line(-hx, -hy, hx, -hy);  // touchlines
  line(-hx, hy, hx, hy);
  line(-hx, -hy, -hx, hy);  // goal lines
  line(hx, -hy, hx, hy);
  line(0, -hy, 0, hy);  // halfway line
  for (int side : {-1, 1}) {
    for (const auto& area : {f.penalty_area, f.goal_area}) {
      if (!area) continue;
      const double x_in = side * (hx - area->length);
      const double w = 0.5 * area->width;
      line(side * hx, -w, x_in, -w);
      line(side * hx, w, x_in, w);
      line(x_in, -w, x_in, w);
    }
    if (f.penalty_mark_distance) f.marks.emplace_back(side * (hx - *f.penalty_mark_distance), 0.0);
  }
  f.marks.emplace_back(0.0, 0.0);
  f.circles.push_back({Vec2(0, 0), f.centre_circle_radius});
}

}  // namespace

double FieldModel::ballRollingDeceleration() const {
  const double g = 9.81;
  return 5.0 * ball.material.rolling_friction * carpet.friction * g / (7.0 * ball.radius);
}

int FieldModel::goalReachedByRollingBall(double x, double y, double vx, double vy) const {
  if (vx == 0.0) return 0;
  const int side = vx > 0 ? 1 : -1;
  // Wholly over the goal line: the line's far edge plus the radius (as the referee counts).
  const double line_x = side * (halfLength() + 0.5 * line_width + ball.radius);
  const double to_line = (line_x - x) / vx;  // s at the present speed, along the path
  if (to_line < 0) return 0;
  const double y_at_line = y + vy * to_line;
  if (std::abs(y_at_line) > 0.5 * goal.inner_width - ball.radius) return 0;
  const double speed = std::hypot(vx, vy);
  const double path = speed * to_line;
  return ballRollingDistance(speed) >= path ? side : 0;
}

double FieldModel::ballRollingDistance(double speed) const {
  const double a = ballRollingDeceleration();
  const double k = -std::log(1.0 - std::clamp(ball.linear_damping, 0.0, 0.999));
  if (k < 1e-9) return speed * speed / (2.0 * a);
  if (a <= 0.0) return speed / k;
  return speed / k - a / (k * k) * std::log1p(k * speed / a);
}

bool FieldModel::onCarpet(double x, double y) const {
  return std::abs(x) <= halfLength() + border && std::abs(y) <= halfWidth() + border;
}

std::vector<Shape> FieldModel::goalShapes(int side) const {
  const double s = side >= 0 ? 1.0 : -1.0;
  const double r = 0.5 * goal.post_diameter;
  const double post_y = postCentreY();
  const double top = goal.clear_height + goal.post_diameter;  // top of the crossbar
  const double x_line = s * halfLength();
  const double t = goal.net_thickness;
  std::vector<Shape> shapes;
  auto add = [&](ShapeType type, const Vec3& centre, const Vec3& extents, double radius,
                 double length, const Eigen::Matrix3d& rot) {
    Shape sh;
    sh.type = type;
    sh.extents = extents;
    sh.radius = radius;
    sh.length = length;
    sh.pose = engine::Pose::Identity();
    sh.pose.linear() = rot;
    sh.pose.translation() = centre;
    shapes.push_back(sh);
  };
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d along_y = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  // Posts from the ground to the top of the crossbar; crossbar between their centres.
  for (double y : {-post_y, post_y})
    add(ShapeType::Cylinder, Vec3(x_line, y, 0.5 * top), Vec3::Zero(), r, top, I);
  add(ShapeType::Cylinder, Vec3(x_line, 0, goal.clear_height + r), Vec3::Zero(), r, 2 * post_y,
      along_y);
  // Net: back wall, two side walls and the roof, behind the goal line.
  const double x_back = x_line + s * (goal.depth + 0.5 * t);
  const double x_mid = x_line + s * 0.5 * goal.depth;
  add(ShapeType::Box, Vec3(x_back, 0, 0.5 * goal.clear_height),
      Vec3(t, 2 * post_y, goal.clear_height), 0, 0, I);
  for (double y : {-post_y, post_y})
    add(ShapeType::Box, Vec3(x_mid, y, 0.5 * goal.clear_height),
        Vec3(goal.depth, t, goal.clear_height), 0, 0, I);
  add(ShapeType::Box, Vec3(x_mid, 0, goal.clear_height + 0.5 * t), Vec3(goal.depth, 2 * post_y, t),
      0, 0, I);
  return shapes;
}

FieldModel loadFieldModel(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"field", "length", "width", "border", "line_width", "centre_circle_diameter",
                  "penalty_mark", "penalty_area", "goal_area", "goal", "carpet", "ball"});
  FieldModel f;
  f.name = root["field"].string();
  f.source_file = file.string();
  f.length = root["length"].positive();
  f.width = root["width"].positive();
  f.border = root["border"].nonNegative();
  // Physically sensible: the largest soccer pitch is 120 x 90 m.
  if (f.length > 200.0) root.failKey("length", "more than 200 m is no soccer field");
  if (f.width > 200.0) root.failKey("width", "more than 200 m is no soccer field");
  if (f.border > 100.0) root.failKey("border", "more than 100 m is no field's border");
  f.line_width = root["line_width"].positive();
  f.centre_circle_radius = 0.5 * root["centre_circle_diameter"].positive();
  if (auto pm = root.optional("penalty_mark")) {
    pm->allowOnly({"distance", "size"});
    f.penalty_mark_distance = (*pm)["distance"].positive();
    f.penalty_mark_size = (*pm)["size"].positive();
    if (*f.penalty_mark_distance >= f.halfLength())
      pm->failKey("distance", "beyond the halfway line");
  }
  for (const char* key : {"penalty_area", "goal_area"}) {
    if (auto a = root.optional(key)) {
      a->allowOnly({"length", "width"});
      AreaSize s{(*a)["length"].positive(), (*a)["width"].positive()};
      if (s.length >= f.halfLength()) a->failKey("length", "beyond the halfway line");
      if (s.width > f.width) a->failKey("width", "wider than the field");
      (std::string(key) == "penalty_area" ? f.penalty_area : f.goal_area) = s;
    }
  }
  const ConfigNode g = root["goal"];
  g.allowOnly(
      {"inner_width", "clear_height", "depth", "post_diameter", "net_thickness", "material"});
  f.goal.inner_width = g["inner_width"].positive();
  f.goal.clear_height = g["clear_height"].positive();
  f.goal.depth = g["depth"].positive();
  f.goal.post_diameter = g["post_diameter"].positive();
  f.goal.net_thickness = g["net_thickness"].positive();
  if (auto m = g.optional("material")) f.goal.material = engine::readMaterial(*m, {});
  if (f.goal.depth > f.border) g.failKey("depth", "the goal must fit on the border carpet");
  if (f.goal.inner_width >= f.width) g.failKey("inner_width", "wider than the field");
  f.carpet = engine::readMaterial(root["carpet"], {});
  const ConfigNode b = root["ball"];
  b.allowOnly({"radius", "mass", "material", "linear_damping", "angular_damping"});
  f.ball.radius = b["radius"].positive();
  f.ball.mass = b["mass"].positive();
  if (f.ball.radius > 0.5) b.failKey("radius", "more than 0.5 m is no ball");
  if (f.ball.mass > 10.0) b.failKey("mass", "more than 10 kg is no ball");
  if (auto m = b.optional("material")) f.ball.material = engine::readMaterial(*m, {});
  f.ball.linear_damping = b.has("linear_damping") ? b["linear_damping"].nonNegative() : 0.0;
  f.ball.angular_damping = b.has("angular_damping") ? b["angular_damping"].nonNegative() : 0.0;
  for (const char* key : {"linear_damping", "angular_damping"})
    if (b.has(key) && b[key].number() >= 1.0) b.failKey(key, "must be below 1");
  buildMarkings(f);
  return f;
}

}  // namespace simsoccer::fields

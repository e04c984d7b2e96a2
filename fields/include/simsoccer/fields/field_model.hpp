// A soccer field loaded from YAML: dimensions, the line markings derived
// from them (for rendering and the referee, not collision), the goals'
// collision primitives, the carpet and the ball.
//
// Field frame: origin at the centre mark, x towards the goal at +x, y left,
// z up; metres.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::fields {

using Vec2 = Eigen::Vector2d;

struct LineSegment {
  Vec2 a, b;  // centre line of a painted line
};
struct Circle {
  Vec2 centre;
  double radius = 0.0;  // to the centre of the line
};
struct AreaSize {
  double length = 0.0;  // depth from the goal line
  double width = 0.0;
};
struct GoalModel {
  double inner_width = 0.0;   // between the posts' inner faces
  double clear_height = 0.0;  // ground to the underside of the crossbar
  double depth = 0.0;         // goal line to the back of the net
  double post_diameter = 0.0;
  double net_thickness = 0.0;
  engine::Material material;
};
struct BallModel {
  double radius = 0.0;
  double mass = 0.0;
  engine::Material material;
  double linear_damping = 0.0;
  double angular_damping = 0.0;
};

struct FieldModel {
  std::string name;
  std::string source_file;
  double length = 0.0, width = 0.0, border = 0.0, line_width = 0.0;
  double centre_circle_radius = 0.0;
  std::optional<double> penalty_mark_distance;
  double penalty_mark_size = 0.0;
  std::optional<AreaSize> penalty_area, goal_area;
  GoalModel goal;
  engine::Material carpet;
  BallModel ball;

  // Markings derived from the dimensions.
  std::vector<LineSegment> lines;
  std::vector<Circle> circles;
  std::vector<Vec2> marks;  // centre mark and penalty marks (crosses)

  double halfLength() const { return 0.5 * length; }
  double halfWidth() const { return 0.5 * width; }
  // The goal posts' centres lie on the goal lines at y = +-postCentreY().
  double postCentreY() const { return 0.5 * goal.inner_width + 0.5 * goal.post_diameter; }
  // Inside the carpet (field plus border).
  bool onCarpet(double x, double y) const;
  // The ball's deceleration rolling on the carpet, m/s^2: a solid sphere with Bullet's
  // rolling friction c (the ball's times the carpet's: Bullet multiplies them) slows at
  // 5 c g / (7 r). The ball's linear damping (turf drag) comes on top.
  double ballRollingDeceleration() const;
  // How far a ball rolling at `speed` m/s goes before it stops, m: slowed at that deceleration
  // a and by its linear damping d (Bullet scales the velocity by (1 - d)^dt: dv/dt = -a - k v,
  // k = -ln(1 - d)), v/k - a/k^2 ln(1 + k v / a); v^2 / (2a) without damping.
  double ballRollingDistance(double speed) const;
  // The goal (+1 or -1, 0: neither) whose mouth a ball rolling from (x, y) at (vx, vy) m/s
  // would cross, all of it between the posts, before rolling to a stop.
  int goalReachedByRollingBall(double x, double y, double vx, double vy) const;
  // Collision primitives of the goal behind the goal line at x = side * length / 2
  // (side = +1 or -1), in the field frame.
  std::vector<engine::Shape> goalShapes(int side) const;
};

FieldModel loadFieldModel(const std::filesystem::path& file);

}  // namespace simsoccer::fields

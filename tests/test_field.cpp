// Field descriptions: dimensions, derived markings and goal geometry.
#include <gtest/gtest.h>

#include <cmath>

#include "simsoccer/fields/field_model.hpp"
#include "test_support.hpp"

using namespace simsoccer;

TEST(Field, SplDimensions) {
  const auto f = fields::loadFieldModel(test::splField());
  EXPECT_DOUBLE_EQ(f.length, 9.0);
  EXPECT_DOUBLE_EQ(f.width, 6.0);
  EXPECT_DOUBLE_EQ(f.border, 0.7);
  EXPECT_DOUBLE_EQ(f.centre_circle_radius, 0.75);
  EXPECT_DOUBLE_EQ(f.ball.radius, 0.05);
  EXPECT_DOUBLE_EQ(f.ball.mass, 0.044);
  ASSERT_TRUE(f.penalty_area && f.goal_area);
  // 4 boundary lines + halfway line + 3 lines per area and side.
  EXPECT_EQ(f.lines.size(), 5u + 2u * 2u * 3u);
  EXPECT_EQ(f.marks.size(), 3u);
  EXPECT_DOUBLE_EQ(f.marks[0].x(), -3.2);  // penalty marks at (+-3.2, 0)
  EXPECT_TRUE(f.onCarpet(5.2, 3.7));
  EXPECT_FALSE(f.onCarpet(5.25, 0.0));
}

TEST(Field, GoalPostsAndCrossbar) {
  const auto f = fields::loadFieldModel(test::splField());
  const auto shapes = f.goalShapes(+1);
  ASSERT_GE(shapes.size(), 3u);
  // Posts centred on the goal line, inner faces 1.5 m apart.
  EXPECT_DOUBLE_EQ(shapes[0].pose.translation().x(), 4.5);
  EXPECT_NEAR(
      shapes[1].pose.translation().y() - shapes[0].pose.translation().y() - 2 * shapes[0].radius,
      1.5, 1e-12);
  // Crossbar underside at 0.8 m.
  EXPECT_NEAR(shapes[2].pose.translation().z() - shapes[2].radius, 0.8, 1e-12);
  const auto other = f.goalShapes(-1);
  EXPECT_DOUBLE_EQ(other[0].pose.translation().x(), -4.5);
}

TEST(Field, SimLeagueField) {
  const auto f = fields::loadFieldModel(test::sourceDir() / "fields" / "simleague.yaml");
  EXPECT_DOUBLE_EQ(f.length, 30.0);
  EXPECT_DOUBLE_EQ(f.width, 20.0);
  EXPECT_FALSE(f.goal_area.has_value());
  EXPECT_DOUBLE_EQ(f.goal.inner_width, 2.1);
}

// The HSL 2026 fields (HSL-Rules field generator data, between line centres):
// the penalty marks land on whole metres, 5 m (M) and 3 m (S) from the centre.
TEST(Field, HslMiddleDivisionFields) {
  const auto m = fields::loadFieldModel(test::sourceDir() / "fields" / "hsl_m.yaml");
  EXPECT_DOUBLE_EQ(m.length + m.line_width, 14.0);  // outside to outside
  EXPECT_DOUBLE_EQ(m.width + m.line_width, 9.0);
  ASSERT_TRUE(m.penalty_area && m.goal_area);
  EXPECT_DOUBLE_EQ(m.penalty_area->width, 5.95);
  EXPECT_NEAR(m.marks[0].x(), -5.0, 1e-12);
  EXPECT_DOUBLE_EQ(m.goal.inner_width, 2.4);
  EXPECT_NEAR(m.ball.radius * 2 * M_PI, 0.59, 0.001);  // FIFA size 3: 0.58-0.60 m around
  EXPECT_GE(m.ball.mass, 0.30);
  EXPECT_LE(m.ball.mass, 0.32);
  const auto post = m.goalShapes(+1);
  EXPECT_NEAR(post[1].pose.translation().y() - post[0].pose.translation().y() - 2 * post[0].radius,
              2.4, 1e-12);

  const auto s = fields::loadFieldModel(test::sourceDir() / "fields" / "hsl_s.yaml");
  EXPECT_DOUBLE_EQ(s.length + s.line_width, 9.0);
  EXPECT_DOUBLE_EQ(s.width + s.line_width, 6.0);
  EXPECT_NEAR(s.marks[0].x(), -3.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.goal.inner_width, 1.8);
  EXPECT_DOUBLE_EQ(s.ball.radius, m.ball.radius);
  // The Small division's (Naos): the S-Field's markings and goals, the SPL's ball.
  const auto small = fields::loadFieldModel(test::sourceDir() / "fields" / "hsl_s_small.yaml");
  const auto spl = fields::loadFieldModel(test::sourceDir() / "fields" / "spl.yaml");
  EXPECT_DOUBLE_EQ(small.length, s.length);
  EXPECT_DOUBLE_EQ(small.goal.inner_width, s.goal.inner_width);
  EXPECT_DOUBLE_EQ(small.goal.clear_height, s.goal.clear_height);
  EXPECT_DOUBLE_EQ(small.goal_area->length, s.goal_area->length);
  EXPECT_DOUBLE_EQ(small.marks[0].x(), s.marks[0].x());
  EXPECT_DOUBLE_EQ(small.ball.radius, spl.ball.radius);
  EXPECT_DOUBLE_EQ(small.ball.mass, spl.ball.mass);
}

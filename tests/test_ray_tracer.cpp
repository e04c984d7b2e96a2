// The batched ray tracer against closed-form answers, primitive by primitive.
#include <gtest/gtest.h>

#include <cmath>

#include "simsoccer/engine/ray_tracer.hpp"

using namespace simsoccer::engine;

namespace {

RayHit traceOne(RayScene& scene, const Vec3f& origin, const Vec3f& dir, float range = 10.0f,
                int32_t exclude = kNoOwner) {
  Ray r;
  r.origin = origin;
  r.direction = dir.normalized();
  r.max_distance = range;
  r.exclude_owner = exclude;
  RayHit h;
  scene.trace(std::span<const Ray>(&r, 1), std::span<RayHit>(&h, 1));
  return h;
}

}  // namespace

TEST(RayScene, SphereCapsuleBoxCylinderGround) {
  RayScene scene;
  scene.setGround(0);
  scene.addSphere({2, 0, 1}, 0.5f, 1, kNoOwner);
  scene.addCapsule({0, 3, 0.5f}, {0, 3, 1.5f}, 0.25f, 2, kNoOwner);
  const Mat3f yaw45 =
      Eigen::AngleAxisf(static_cast<float>(M_PI / 4), Vec3f::UnitZ()).toRotationMatrix();
  scene.addBox({-3, 0, 1}, yaw45, {0.5f, 0.5f, 0.5f}, 3, kNoOwner);
  scene.addCylinder({0, -3, 1}, {0, 0, 1}, 0.5f, 0.2f, 4, kNoOwner);
  scene.finalize();
  const Vec3f o(0, 0, 1);
  RayHit h = traceOne(scene, o, {1, 0, 0});
  EXPECT_EQ(h.object, 1);
  EXPECT_NEAR(h.distance, 1.5f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(Vec3f(-1, 0, 0), 1e-5f));
  h = traceOne(scene, o, {0, 1, 0});
  EXPECT_EQ(h.object, 2);
  EXPECT_NEAR(h.distance, 2.75f, 1e-5f);
  h = traceOne(scene, o, {0, 1, 0.5f});  // over the top cap: hits the hemisphere
  EXPECT_EQ(h.object, kNoObject);        // passes above (z at y=3 is 2.5)
  h = traceOne(scene, o, {-1, 0, 0});
  EXPECT_EQ(h.object, 3);
  EXPECT_NEAR(h.distance, 3.0f - 0.5f * std::sqrt(2.0f), 1e-5f);  // box corner towards us
  h = traceOne(scene, o, {0, -1, 0});
  EXPECT_EQ(h.object, 4);
  EXPECT_NEAR(h.distance, 2.8f, 1e-5f);
  h = traceOne(scene, {0, -3, 2}, {0, 0, -1});  // down onto the cylinder's top cap
  EXPECT_EQ(h.object, 4);
  EXPECT_NEAR(h.distance, 0.5f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(Vec3f(0, 0, 1), 1e-5f));
  h = traceOne(scene, o, {1, 1, -1});  // down to the carpet
  EXPECT_EQ(h.object, 0);
  EXPECT_NEAR(h.distance, std::sqrt(3.0f), 1e-5f);
  h = traceOne(scene, o, {1, 0, 0}, 1.2f);  // out of range
  EXPECT_EQ(h.object, kNoObject);
  EXPECT_TRUE(std::isinf(h.distance));
}

TEST(RayScene, OwnerExclusionAndBroadphase) {
  RayScene scene;
  for (int owner = 0; owner < 5; ++owner)
    for (int k = 0; k < 3; ++k)
      scene.addSphere({static_cast<float>(owner), static_cast<float>(k) * 0.1f, 0}, 0.05f,
                      owner * 10 + k, owner);
  scene.finalize();
  // From inside owner 0's spheres along +x: owner 0 is skipped, owner 1 hit.
  RayHit h = traceOne(scene, {0, 0, 0}, {1, 0, 0}, 10.0f, 0);
  EXPECT_EQ(h.object, 10);
  EXPECT_NEAR(h.distance, 0.95f, 1e-5f);
  // Not excluded: the ray starts inside a sphere of owner 0 (distance 0).
  h = traceOne(scene, {0, 0, 0}, {1, 0, 0});
  EXPECT_EQ(h.object, 0);
  EXPECT_FLOAT_EQ(h.distance, 0.0f);
  // Primitives added out of owner order are regrouped.
  RayScene mixed;
  mixed.addSphere({5, 0, 0}, 0.1f, 7, 3);
  mixed.addSphere({2, 0, 0}, 0.1f, 8, 1);
  mixed.addSphere({3, 0, 0}, 0.1f, 9, 3);
  mixed.finalize();
  EXPECT_EQ(traceOne(mixed, {0, 0, 0}, {1, 0, 0}, 10.0f, 1).object, 9);
}

TEST(RayScene, CapsCornersAndTiltedShapes) {
  RayScene scene;
  // Capsule along z from (0,0,0) to (0,0,1), radius 0.2: hit its top cap.
  scene.addCapsule({0, 0, 0}, {0, 0, 1}, 0.2f, 1, kNoOwner);
  // Box rotated 30 deg about x, half extents 0.5 x 0.3 x 0.1, at (5, 0, 0).
  const Mat3f tilt =
      Eigen::AngleAxisf(static_cast<float>(M_PI / 6), Vec3f::UnitX()).toRotationMatrix();
  scene.addBox({5, 0, 0}, tilt, {0.5f, 0.3f, 0.1f}, 2, kNoOwner);
  // Cylinder tilted 45 deg in the x-z plane at (0, 5, 0), radius 0.1, half length 0.5.
  scene.addCylinder({0, 5, 0}, Vec3f(1, 0, 1).normalized(), 0.5f, 0.1f, 3, kNoOwner);
  scene.finalize();

  RayHit h = traceOne(scene, {0, 0, 3}, {0, 0, -1});  // straight down onto the cap
  EXPECT_EQ(h.object, 1);
  EXPECT_NEAR(h.distance, 3.0f - 1.2f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(Vec3f(0, 0, 1), 1e-5f));
  h = traceOne(scene, {0.15f, 0, 3}, {0, 0, -1});  // off-centre on the cap's sphere
  EXPECT_NEAR(h.distance, 3.0f - (1.0f + std::sqrt(0.04f - 0.0225f)), 1e-5f);
  h = traceOne(scene, {-2, 0, 0.5f}, {1, 0, 0});  // the body, side on
  EXPECT_NEAR(h.distance, 1.8f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(Vec3f(-1, 0, 0), 1e-5f));
  h = traceOne(scene, {0, 0, 0.5f}, {1, 0, 0});  // from inside: 0, as spheres and boxes
  EXPECT_EQ(h.object, 1);
  EXPECT_FLOAT_EQ(h.distance, 0.0f);

  // The tilted box from above: its top face's plane through the centre.
  h = traceOne(scene, {5, 0, 2}, {0, 0, -1});
  EXPECT_EQ(h.object, 2);
  EXPECT_NEAR(h.distance, 2.0f - 0.1f / std::cos(static_cast<float>(M_PI / 6)), 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(tilt.col(2), 1e-5f));

  // The tilted cylinder, along its axis from below-left: hits the bottom cap.
  const Vec3f axis = Vec3f(1, 0, 1).normalized();
  h = traceOne(scene, Vec3f(0, 5, 0) - 2.0f * axis, axis);
  EXPECT_EQ(h.object, 3);
  EXPECT_NEAR(h.distance, 1.5f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(-axis, 1e-5f));
  // Across its side at the centre: radius 0.1 along the perpendicular.
  const Vec3f across = Vec3f(1, 0, -1).normalized();
  h = traceOne(scene, Vec3f(0, 5, 0) - 1.0f * across, across);
  EXPECT_NEAR(h.distance, 0.9f, 1e-5f);
  EXPECT_TRUE(h.normal.isApprox(-across, 1e-4f));
}

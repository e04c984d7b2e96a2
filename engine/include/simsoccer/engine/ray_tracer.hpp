// Batched ray casting against collision primitives (sonar and other range
// sensors). The scene is a structure of arrays per primitive type, grouped by
// owner (a robot) with one bounding sphere per owner as the broadphase; all
// rays are traced in one call. Primitives without an owner (ground, goals,
// ball) are tested by every ray.
//
// Single precision, world frame, metres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace simsoccer::engine {

using Vec3f = Eigen::Vector3f;
using Mat3f = Eigen::Matrix3f;

constexpr int32_t kNoObject = -1;
constexpr int32_t kNoOwner = -1;

struct Ray {
  Vec3f origin = Vec3f::Zero();
  Vec3f direction = Vec3f::UnitX();  // unit
  float max_distance = 1.0f;
  int32_t exclude_owner = kNoOwner;  // primitives of this owner are invisible to the ray
};

struct RayHit {
  float distance = std::numeric_limits<float>::infinity();  // inf: nothing within range
  int32_t object = kNoObject;
  Vec3f normal = Vec3f::Zero();  // outward surface normal at the hit, world frame
};

class RayScene {
 public:
  void clear();
  // The ground plane z = 0 (seen from above).
  void setGround(int32_t object);
  void addSphere(const Vec3f& centre, float radius, int32_t object, int32_t owner);
  // Segment p0-p1 swept by a sphere of `radius`.
  void addCapsule(const Vec3f& p0, const Vec3f& p1, float radius, int32_t object, int32_t owner);
  // Oriented box: rotation columns are the box axes in the world.
  void addBox(const Vec3f& centre, const Mat3f& rotation, const Vec3f& half_extents, int32_t object,
              int32_t owner);
  // Capped cylinder along the unit `axis` through `centre`.
  void addCylinder(const Vec3f& centre, const Vec3f& axis, float half_length, float radius,
                   int32_t object, int32_t owner);
  // Groups primitives by owner and computes the owners' bounding spheres.
  // Call after adding, before tracing.
  void finalize();

  // hits[i] = the nearest hit of rays[i] within its max distance.
  void trace(std::span<const Ray> rays, std::span<RayHit> hits) const;

  size_t primitiveCount() const;

 private:
  struct Spheres {
    std::vector<float> cx, cy, cz, r;
    std::vector<int32_t> object, owner;
  } spheres_;
  struct Capsules {
    std::vector<float> ax, ay, az, bx, by, bz, r;
    std::vector<int32_t> object, owner;
  } capsules_;
  struct Boxes {
    std::vector<float> cx, cy, cz, hx, hy, hz;
    std::vector<float> r[9];  // rotation, row-major
    std::vector<int32_t> object, owner;
  } boxes_;
  struct Cylinders {
    std::vector<float> cx, cy, cz, ux, uy, uz, h, r;
    std::vector<int32_t> object, owner;
  } cylinders_;
  int32_t ground_object_ = kNoObject;
  bool has_ground_ = false;

  // After finalize(): per owner group (group 0 = no owner), the ranges of
  // each primitive type and a bounding sphere.
  struct Group {
    int32_t owner = kNoOwner;
    uint32_t sphere_begin = 0, sphere_end = 0, capsule_begin = 0, capsule_end = 0, box_begin = 0,
             box_end = 0, cylinder_begin = 0, cylinder_end = 0;
    Vec3f centre = Vec3f::Zero();
    float radius = 0.0f;
  };
  std::vector<Group> groups_;

  // The primitive a ray stopped on (to compute its normal once, at the end).
  enum class Kind : uint8_t { None, Ground, Sphere, Capsule, Box, Cylinder };
  struct Best {
    Kind kind = Kind::None;
    uint32_t index = 0;
  };
  void traceGroup(const Group& g, const Ray& ray, RayHit& hit, Best& best) const;
  Vec3f normalAt(const Best& best, const Vec3f& point) const;
};

}  // namespace simsoccer::engine

// Batched ray casting against collision primitives (sonar and other range
// sensors). The scene is a structure of arrays per primitive type, grouped by
// owner with one bounding sphere per owner as the broadphase; all rays are
// traced in one call. Owners >= 0 are robots (a ray can exclude its own);
// negative owners group static or free objects (a goal, the ball) and are
// never excluded.
//
// Single precision, world frame, metres.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <initializer_list>
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
  // `owner` >= 0 is a robot (rays may exclude their own); negative owners
  // group other objects (a goal, the ball). `cluster` splits an owner into
  // broadphase groups with their own bounding spheres (a robot's limbs), so
  // a ray passing near a robot tests only the limbs it passes.
  void addSphere(const Vec3f& centre, float radius, int32_t object, int32_t owner,
                 uint8_t cluster = 0);
  // Segment p0-p1 swept by a sphere of `radius`.
  void addCapsule(const Vec3f& p0, const Vec3f& p1, float radius, int32_t object, int32_t owner,
                  uint8_t cluster = 0);
  // Oriented box: rotation columns are the box axes in the world.
  void addBox(const Vec3f& centre, const Mat3f& rotation, const Vec3f& half_extents, int32_t object,
              int32_t owner, uint8_t cluster = 0);
  // Capped cylinder along the unit `axis` through `centre`.
  void addCylinder(const Vec3f& centre, const Vec3f& axis, float half_length, float radius,
                   int32_t object, int32_t owner, uint8_t cluster = 0);
  // Groups primitives by (owner, cluster) and computes the groups' bounding
  // spheres. Call after adding, before tracing.
  void finalize();

  // hits[i] = the nearest hit of rays[i] within its max distance. Not const:
  // it keeps its scratch (no allocation once warm).
  void trace(std::span<const Ray> rays, std::span<RayHit> hits);
  // Spheres, capsules, boxes and cylinders added since the last clear().
  size_t primitiveCount() const;

 private:
  // One primitive type as columns of floats (structure of arrays), with the
  // object each primitive belongs to and its group key (owner * 256 + cluster).
  struct Columns {
    std::vector<std::vector<float>> values;
    std::vector<int32_t> object;
    std::vector<int64_t> key;
    explicit Columns(size_t n) : values(n) {}
    size_t size() const { return object.size(); }
    void clear();
    void push(std::initializer_list<float> row, int32_t object, int64_t key);
    void sortByKey();
  };
  Columns spheres_{4};    // cx cy cz r
  Columns capsules_{7};   // ax ay az bx by bz r
  Columns boxes_{15};     // cx cy cz hx hy hz r00 r01 r02 r10 r11 r12 r20 r21 r22
  Columns cylinders_{8};  // cx cy cz ux uy uz half_length r
  int32_t ground_object_ = kNoObject;
  bool has_ground_ = false;

  // After finalize(): per group, the ranges of each primitive type and a
  // bounding sphere.
  struct Group {
    int32_t owner = kNoOwner;
    uint32_t sphere_begin = 0, sphere_end = 0, capsule_begin = 0, capsule_end = 0, box_begin = 0,
             box_end = 0, cylinder_begin = 0, cylinder_end = 0;
    Vec3f centre = Vec3f::Zero();
    float radius = 0.0f;
  };
  std::vector<Group> groups_;
  // Consecutive groups of one owner, with a sphere around all of them: the
  // first broadphase level (a ray tests an owner's clusters only if it
  // passes the owner's sphere).
  struct Block {
    int32_t owner = kNoOwner;
    uint32_t group_begin = 0, group_end = 0;
    Vec3f centre = Vec3f::Zero();
    float radius = 0.0f;
  };
  std::vector<Block> blocks_;
  std::vector<uint32_t> near_;  // trace's scratch: the blocks within the current rays' reach

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

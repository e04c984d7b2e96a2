#include "simsoccer/engine/ray_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace simsoccer::engine {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kEps = 1e-12f;

inline int64_t groupKey(int32_t owner, uint8_t cluster) {
  return static_cast<int64_t>(owner) * 256 + cluster;
}
// The owner part of a key (floor division, negative owners included).
inline int32_t keyOwner(int64_t key) {
  return static_cast<int32_t>(key >= 0 ? key / 256 : -((-key + 255) / 256));
}

// First entry distance of a ray into a sphere, or inf. A ray starting inside
// hits at 0.
inline float raySphere(float ox, float oy, float oz, float dx, float dy, float dz, float cx,
                       float cy, float cz, float r) {
  const float px = ox - cx, py = oy - cy, pz = oz - cz;
  const float b = px * dx + py * dy + pz * dz;
  const float c = px * px + py * py + pz * pz - r * r;
  if (c <= 0.0f) return 0.0f;
  const float disc = b * b - c;
  if (disc < 0.0f || b > 0.0f) return kInf;
  return -b - std::sqrt(disc);
}

}  // namespace

void RayScene::Columns::clear() {
  for (auto& c : values) c.clear();
  object.clear();
  key.clear();
}

void RayScene::Columns::push(std::initializer_list<float> row, int32_t obj, int64_t k) {
  size_t i = 0;
  for (float v : row) values[i++].push_back(v);
  object.push_back(obj);
  key.push_back(k);
}

void RayScene::Columns::sortByKey() {
  if (std::is_sorted(key.begin(), key.end())) return;  // the usual case: added in order
  std::vector<uint32_t> order(key.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return key[a] < key[b]; });
  auto permute = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(v.size());
    for (size_t i = 0; i < order.size(); ++i) out[i] = v[order[i]];
    v.swap(out);
  };
  for (auto& c : values) permute(c);
  permute(object);
  permute(key);
}

void RayScene::clear() {
  // Keeps the arrays' capacity: rebuilding the scene every sonar update
  // allocates nothing once the first one has sized them.
  for (Columns* c : {&spheres_, &capsules_, &boxes_, &cylinders_}) c->clear();
  groups_.clear();
  blocks_.clear();
  has_ground_ = false;
  ground_object_ = kNoObject;
}

void RayScene::setGround(int32_t object) {
  has_ground_ = true;
  ground_object_ = object;
}

void RayScene::addSphere(const Vec3f& c, float radius, int32_t object, int32_t owner,
                         uint8_t cluster) {
  spheres_.push({c.x(), c.y(), c.z(), radius}, object, groupKey(owner, cluster));
}

void RayScene::addCapsule(const Vec3f& p0, const Vec3f& p1, float radius, int32_t object,
                          int32_t owner, uint8_t cluster) {
  capsules_.push({p0.x(), p0.y(), p0.z(), p1.x(), p1.y(), p1.z(), radius}, object,
                 groupKey(owner, cluster));
}

void RayScene::addBox(const Vec3f& c, const Mat3f& r, const Vec3f& half, int32_t object,
                      int32_t owner, uint8_t cluster) {
  boxes_.push({c.x(), c.y(), c.z(), half.x(), half.y(), half.z(), r(0, 0), r(0, 1), r(0, 2),
               r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)},
              object, groupKey(owner, cluster));
}

void RayScene::addCylinder(const Vec3f& c, const Vec3f& axis, float half_length, float radius,
                           int32_t object, int32_t owner, uint8_t cluster) {
  const Vec3f u = axis.normalized();
  cylinders_.push({c.x(), c.y(), c.z(), u.x(), u.y(), u.z(), half_length, radius}, object,
                  groupKey(owner, cluster));
}

void RayScene::finalize() {
  for (Columns* c : {&spheres_, &capsules_, &boxes_, &cylinders_}) c->sortByKey();
  // One group per distinct key, ascending: walk the four sorted key arrays
  // together.
  groups_.clear();
  uint32_t si = 0, ci = 0, bi = 0, yi = 0;
  const auto ns = static_cast<uint32_t>(spheres_.size());
  const auto nc = static_cast<uint32_t>(capsules_.size());
  const auto nb = static_cast<uint32_t>(boxes_.size());
  const auto ny = static_cast<uint32_t>(cylinders_.size());
  constexpr int64_t kEnd = std::numeric_limits<int64_t>::max();
  while (si < ns || ci < nc || bi < nb || yi < ny) {
    const int64_t key =
        std::min({si < ns ? spheres_.key[si] : kEnd, ci < nc ? capsules_.key[ci] : kEnd,
                  bi < nb ? boxes_.key[bi] : kEnd, yi < ny ? cylinders_.key[yi] : kEnd});
    Group g;
    g.owner = keyOwner(key);
    g.sphere_begin = si;
    while (si < ns && spheres_.key[si] == key) ++si;
    g.sphere_end = si;
    g.capsule_begin = ci;
    while (ci < nc && capsules_.key[ci] == key) ++ci;
    g.capsule_end = ci;
    g.box_begin = bi;
    while (bi < nb && boxes_.key[bi] == key) ++bi;
    g.box_end = bi;
    g.cylinder_begin = yi;
    while (yi < ny && cylinders_.key[yi] == key) ++yi;
    g.cylinder_end = yi;

    // Bounding sphere around the primitives' own bounding spheres: centre at
    // their mean, radius to the farthest.
    const auto& S = spheres_.values;
    const auto& C = capsules_.values;
    const auto& B = boxes_.values;
    const auto& Y = cylinders_.values;
    auto each = [&](auto&& f) {
      for (uint32_t i = g.sphere_begin; i < g.sphere_end; ++i)
        f(Vec3f(S[0][i], S[1][i], S[2][i]), S[3][i]);
      for (uint32_t i = g.capsule_begin; i < g.capsule_end; ++i) {
        const Vec3f a(C[0][i], C[1][i], C[2][i]), b(C[3][i], C[4][i], C[5][i]);
        f(0.5f * (a + b), 0.5f * (b - a).norm() + C[6][i]);
      }
      for (uint32_t i = g.box_begin; i < g.box_end; ++i)
        f(Vec3f(B[0][i], B[1][i], B[2][i]), Vec3f(B[3][i], B[4][i], B[5][i]).norm());
      for (uint32_t i = g.cylinder_begin; i < g.cylinder_end; ++i)
        f(Vec3f(Y[0][i], Y[1][i], Y[2][i]), std::hypot(Y[6][i], Y[7][i]));
    };
    Vec3f centre = Vec3f::Zero();
    int count = 0;
    each([&](const Vec3f& c, float) {
      centre += c;
      ++count;
    });
    centre /= static_cast<float>(std::max(count, 1));
    float radius = 0.0f;
    each([&](const Vec3f& c, float r) { radius = std::max(radius, (c - centre).norm() + r); });
    g.centre = centre;
    g.radius = radius * 1.0001f + 1e-5f;
    groups_.push_back(g);
  }

  blocks_.clear();
  for (uint32_t g = 0; g < groups_.size();) {
    Block b;
    b.owner = groups_[g].owner;
    b.group_begin = g;
    while (g < groups_.size() && groups_[g].owner == b.owner) ++g;
    b.group_end = g;
    Vec3f centre = Vec3f::Zero();
    for (uint32_t k = b.group_begin; k < b.group_end; ++k) centre += groups_[k].centre;
    centre /= static_cast<float>(b.group_end - b.group_begin);
    float radius = 0.0f;
    for (uint32_t k = b.group_begin; k < b.group_end; ++k)
      radius = std::max(radius, (groups_[k].centre - centre).norm() + groups_[k].radius);
    b.centre = centre;
    b.radius = radius * 1.0001f + 1e-5f;
    blocks_.push_back(b);
  }
}

void RayScene::traceGroup(const Group& g, const Ray& ray, RayHit& hit, Best& best) const {
  const auto& S = spheres_.values;
  const auto& C = capsules_.values;
  const auto& B = boxes_.values;
  const auto& Y = cylinders_.values;
  const float ox = ray.origin.x(), oy = ray.origin.y(), oz = ray.origin.z();
  const float dx = ray.direction.x(), dy = ray.direction.y(), dz = ray.direction.z();
  Kind kind = Kind::None;
  auto take = [&](float t, int32_t object, uint32_t index) {
    if (t < hit.distance) {
      hit.distance = t;
      hit.object = object;
      best = {kind, index};
    }
  };

  kind = Kind::Sphere;
  for (uint32_t i = g.sphere_begin; i < g.sphere_end; ++i)
    take(raySphere(ox, oy, oz, dx, dy, dz, S[0][i], S[1][i], S[2][i], S[3][i]), spheres_.object[i],
         i);

  kind = Kind::Capsule;
  for (uint32_t i = g.capsule_begin; i < g.capsule_end; ++i) {
    const float ax = C[0][i], ay = C[1][i], az = C[2][i];
    const float bx = C[3][i], by = C[4][i], bz = C[5][i];
    const float r = C[6][i];
    // Cylindrical body between the end caps.
    const float ux = bx - ax, uy = by - ay, uz = bz - az;
    const float px = ox - ax, py = oy - ay, pz = oz - az;
    const float uu = ux * ux + uy * uy + uz * uz;
    const float ud = ux * dx + uy * dy + uz * dz;
    const float up = ux * px + uy * py + uz * pz;
    const float dp = dx * px + dy * py + dz * pz;
    const float pp = px * px + py * py + pz * pz;
    float t = kInf;
    // A ray starting inside reports 0, as for spheres and boxes.
    const float s0 = std::clamp(up / uu, 0.0f, 1.0f);
    const float ix = px - s0 * ux, iy = py - s0 * uy, iz = pz - s0 * uz;
    if (ix * ix + iy * iy + iz * iz <= r * r) t = 0.0f;
    const float A = uu - ud * ud;
    if (A > kEps) {
      const float B = uu * dp - up * ud;
      const float C = uu * pp - up * up - r * r * uu;
      const float h = B * B - A * C;
      if (h >= 0.0f) {
        const float tb = (-B - std::sqrt(h)) / A;
        const float y = up + tb * ud;
        if (tb >= 0.0f && y > 0.0f && y < uu) t = std::min(t, tb);
      }
    }
    t = std::min({t, raySphere(ox, oy, oz, dx, dy, dz, ax, ay, az, r),
                  raySphere(ox, oy, oz, dx, dy, dz, bx, by, bz, r)});
    take(t, capsules_.object[i], i);
  }

  kind = Kind::Box;
  for (uint32_t i = g.box_begin; i < g.box_end; ++i) {
    // Ray in box coordinates: local = R^T (o - c), R^T d.
    const float px = ox - B[0][i], py = oy - B[1][i], pz = oz - B[2][i];
    const float* R[9];
    for (int k = 0; k < 9; ++k) R[k] = &B[6 + k][i];
    const float lo[3] = {*R[0] * px + *R[3] * py + *R[6] * pz, *R[1] * px + *R[4] * py + *R[7] * pz,
                         *R[2] * px + *R[5] * py + *R[8] * pz};
    const float ld[3] = {*R[0] * dx + *R[3] * dy + *R[6] * dz, *R[1] * dx + *R[4] * dy + *R[7] * dz,
                         *R[2] * dx + *R[5] * dy + *R[8] * dz};
    const float h[3] = {B[3][i], B[4][i], B[5][i]};
    float tmin = -kInf, tmax = kInf;
    bool miss = false;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(ld[k]) < 1e-9f) {
        miss = miss || std::abs(lo[k]) > h[k];
      } else {
        const float inv = 1.0f / ld[k];
        const float t1 = (-h[k] - lo[k]) * inv, t2 = (h[k] - lo[k]) * inv;
        tmin = std::max(tmin, std::min(t1, t2));
        tmax = std::min(tmax, std::max(t1, t2));
      }
    }
    if (!miss && tmax >= std::max(tmin, 0.0f)) take(std::max(tmin, 0.0f), boxes_.object[i], i);
  }

  kind = Kind::Cylinder;
  for (uint32_t i = g.cylinder_begin; i < g.cylinder_end; ++i) {
    const float ux = Y[3][i], uy = Y[4][i], uz = Y[5][i];
    const float hh = Y[6][i], r = Y[7][i];
    const float px = ox - Y[0][i], py = oy - Y[1][i], pz = oz - Y[2][i];
    const float oa = px * ux + py * uy + pz * uz;  // along the axis
    const float da = dx * ux + dy * uy + dz * uz;
    const float qx = px - oa * ux, qy = py - oa * uy, qz = pz - oa * uz;  // across
    const float ex = dx - da * ux, ey = dy - da * uy, ez = dz - da * uz;
    float t = kInf;
    if (std::abs(oa) <= hh && qx * qx + qy * qy + qz * qz <= r * r) t = 0.0f;  // starts inside
    const float a = ex * ex + ey * ey + ez * ez;
    const float b = qx * ex + qy * ey + qz * ez;
    const float c = qx * qx + qy * qy + qz * qz - r * r;
    if (a > kEps) {
      const float disc = b * b - a * c;
      if (disc >= 0.0f) {
        const float ts = (-b - std::sqrt(disc)) / a;
        if (ts >= 0.0f && std::abs(oa + ts * da) <= hh) t = std::min(t, ts);
      }
    }
    if (std::abs(da) > 1e-9f) {
      for (const float s : {-hh, hh}) {
        const float tc = (s - oa) / da;
        if (tc < 0.0f || tc >= t) continue;
        const float cx = qx + tc * ex, cy = qy + tc * ey, cz = qz + tc * ez;
        if (cx * cx + cy * cy + cz * cz <= r * r) t = tc;
      }
    }
    take(t, cylinders_.object[i], i);
  }
}

Vec3f RayScene::normalAt(const Best& b, const Vec3f& p) const {
  const auto& S = spheres_.values;
  const auto& C = capsules_.values;
  const auto& B = boxes_.values;
  const auto& Y = cylinders_.values;
  const uint32_t i = b.index;
  switch (b.kind) {
    case Kind::None:
      return Vec3f::Zero();
    case Kind::Ground:
      return Vec3f::UnitZ();
    case Kind::Sphere:
      return (p - Vec3f(S[0][i], S[1][i], S[2][i])).normalized();
    case Kind::Capsule: {
      const Vec3f a(C[0][i], C[1][i], C[2][i]);
      const Vec3f u = Vec3f(C[3][i], C[4][i], C[5][i]) - a;
      const float s = std::clamp((p - a).dot(u) / u.squaredNorm(), 0.0f, 1.0f);
      return (p - (a + s * u)).normalized();
    }
    case Kind::Box: {
      Mat3f r;
      for (int k = 0; k < 9; ++k) r(k / 3, k % 3) = B[6 + k][i];
      const Vec3f local = r.transpose() * (p - Vec3f(B[0][i], B[1][i], B[2][i]));
      const Vec3f h(B[3][i], B[4][i], B[5][i]);
      int axis = 0;
      (local.array().abs() / h.array()).maxCoeff(&axis);
      return r.col(axis) * (local[axis] < 0.0f ? -1.0f : 1.0f);
    }
    case Kind::Cylinder: {
      const Vec3f c(Y[0][i], Y[1][i], Y[2][i]);
      const Vec3f u(Y[3][i], Y[4][i], Y[5][i]);
      const float along = (p - c).dot(u);
      if (std::abs(along) >= Y[6][i] - 1e-5f) return u * (along < 0.0f ? -1.0f : 1.0f);
      return (p - c - along * u).normalized();
    }
  }
  return Vec3f::Zero();
}

size_t RayScene::primitiveCount() const {
  return spheres_.size() + capsules_.size() + boxes_.size() + cylinders_.size();
}

void RayScene::trace(std::span<const Ray> rays, std::span<RayHit> hits) {
  // The blocks a ray could reach, worked out once for the rays that share its
  // origin, range and owner (a sonar's cone): a block further from the origin
  // than the range and its radius cannot pass the per-ray test below (the
  // margin keeps that so under rounding), so the hits are the same.
  const Ray* near_for = nullptr;
  for (size_t k = 0; k < rays.size(); ++k) {
    const Ray& ray = rays[k];
    if (!near_for || ray.origin != near_for->origin || ray.max_distance != near_for->max_distance ||
        ray.exclude_owner != near_for->exclude_owner) {
      near_.clear();
      for (uint32_t i = 0; i < blocks_.size(); ++i) {
        const Block& b = blocks_[i];
        if (b.owner != kNoOwner && b.owner == ray.exclude_owner) continue;
        const float reach = (ray.max_distance + b.radius) * 1.001f + 1e-4f;
        if ((b.centre - ray.origin).squaredNorm() <= reach * reach) near_.push_back(i);
      }
      near_for = &ray;
    }
    RayHit hit;
    Best best;
    hit.distance = ray.max_distance;  // only hits within range count
    if (has_ground_ && ray.direction.z() < 0.0f && ray.origin.z() > 0.0f) {
      const float t = -ray.origin.z() / ray.direction.z();
      if (t < hit.distance) {
        hit.distance = t;
        hit.object = ground_object_;
        best = {Kind::Ground, 0};
      }
    }
    // Does the ray pass within a sphere before the best hit so far?
    auto passes = [&](const Vec3f& centre, float radius) {
      const Vec3f oc = centre - ray.origin;
      const float along = std::clamp(oc.dot(ray.direction), 0.0f, hit.distance);
      return (oc - along * ray.direction).squaredNorm() <= radius * radius;
    };
    for (const uint32_t i : near_) {
      const Block& b = blocks_[i];
      if (!passes(b.centre, b.radius)) continue;
      for (uint32_t k = b.group_begin; k < b.group_end; ++k)
        if (passes(groups_[k].centre, groups_[k].radius)) traceGroup(groups_[k], ray, hit, best);
    }
    if (hit.object == kNoObject)
      hit.distance = kInf;
    else
      hit.normal = normalAt(best, ray.origin + hit.distance * ray.direction);
    hits[k] = hit;
  }
}

}  // namespace simsoccer::engine

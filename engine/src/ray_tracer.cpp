#include "simsoccer/engine/ray_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace simsoccer::engine {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kEps = 1e-12f;

// Reorders every array of a primitive set by a permutation.
template <class T>
void permute(std::vector<T>& v, const std::vector<uint32_t>& order) {
  std::vector<T> out(v.size());
  for (size_t i = 0; i < order.size(); ++i) out[i] = v[order[i]];
  v.swap(out);
}

std::vector<uint32_t> ownerOrder(const std::vector<int32_t>& owner) {
  std::vector<uint32_t> order(owner.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return owner[a] < owner[b]; });
  return order;
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

void RayScene::clear() {
  // Keeps the arrays' capacity: rebuilding the scene every sonar update
  // allocates nothing once the first one has sized them.
  for (auto* v : {&spheres_.cx,   &spheres_.cy,   &spheres_.cz,   &spheres_.r,    &capsules_.ax,
                  &capsules_.ay,  &capsules_.az,  &capsules_.bx,  &capsules_.by,  &capsules_.bz,
                  &capsules_.r,   &boxes_.cx,     &boxes_.cy,     &boxes_.cz,     &boxes_.hx,
                  &boxes_.hy,     &boxes_.hz,     &cylinders_.cx, &cylinders_.cy, &cylinders_.cz,
                  &cylinders_.ux, &cylinders_.uy, &cylinders_.uz, &cylinders_.h,  &cylinders_.r})
    v->clear();
  for (auto& v : boxes_.r) v.clear();
  for (auto* v : {&spheres_.object, &spheres_.owner, &capsules_.object, &capsules_.owner,
                  &boxes_.object, &boxes_.owner, &cylinders_.object, &cylinders_.owner})
    v->clear();
  groups_.clear();
  has_ground_ = false;
  ground_object_ = kNoObject;
}

void RayScene::setGround(int32_t object) {
  has_ground_ = true;
  ground_object_ = object;
}

void RayScene::addSphere(const Vec3f& c, float radius, int32_t object, int32_t owner) {
  spheres_.cx.push_back(c.x());
  spheres_.cy.push_back(c.y());
  spheres_.cz.push_back(c.z());
  spheres_.r.push_back(radius);
  spheres_.object.push_back(object);
  spheres_.owner.push_back(owner);
}

void RayScene::addCapsule(const Vec3f& p0, const Vec3f& p1, float radius, int32_t object,
                          int32_t owner) {
  capsules_.ax.push_back(p0.x());
  capsules_.ay.push_back(p0.y());
  capsules_.az.push_back(p0.z());
  capsules_.bx.push_back(p1.x());
  capsules_.by.push_back(p1.y());
  capsules_.bz.push_back(p1.z());
  capsules_.r.push_back(radius);
  capsules_.object.push_back(object);
  capsules_.owner.push_back(owner);
}

void RayScene::addBox(const Vec3f& c, const Mat3f& rotation, const Vec3f& half, int32_t object,
                      int32_t owner) {
  boxes_.cx.push_back(c.x());
  boxes_.cy.push_back(c.y());
  boxes_.cz.push_back(c.z());
  boxes_.hx.push_back(half.x());
  boxes_.hy.push_back(half.y());
  boxes_.hz.push_back(half.z());
  for (int k = 0; k < 9; ++k) boxes_.r[k].push_back(rotation(k / 3, k % 3));
  boxes_.object.push_back(object);
  boxes_.owner.push_back(owner);
}

void RayScene::addCylinder(const Vec3f& c, const Vec3f& axis, float half_length, float radius,
                           int32_t object, int32_t owner) {
  const Vec3f u = axis.normalized();
  cylinders_.cx.push_back(c.x());
  cylinders_.cy.push_back(c.y());
  cylinders_.cz.push_back(c.z());
  cylinders_.ux.push_back(u.x());
  cylinders_.uy.push_back(u.y());
  cylinders_.uz.push_back(u.z());
  cylinders_.h.push_back(half_length);
  cylinders_.r.push_back(radius);
  cylinders_.object.push_back(object);
  cylinders_.owner.push_back(owner);
}

size_t RayScene::primitiveCount() const {
  return spheres_.r.size() + capsules_.r.size() + boxes_.hx.size() + cylinders_.r.size();
}

void RayScene::finalize() {
  // Group the primitives by owner (callers that add them owner by owner, as
  // the sensor system does, skip the reordering and its allocations).
  if (!std::is_sorted(spheres_.owner.begin(), spheres_.owner.end())) {
    const auto o = ownerOrder(spheres_.owner);
    for (auto* v : {&spheres_.cx, &spheres_.cy, &spheres_.cz, &spheres_.r}) permute(*v, o);
    permute(spheres_.object, o);
    permute(spheres_.owner, o);
  }
  if (!std::is_sorted(capsules_.owner.begin(), capsules_.owner.end())) {
    const auto o = ownerOrder(capsules_.owner);
    for (auto* v : {&capsules_.ax, &capsules_.ay, &capsules_.az, &capsules_.bx, &capsules_.by,
                    &capsules_.bz, &capsules_.r})
      permute(*v, o);
    permute(capsules_.object, o);
    permute(capsules_.owner, o);
  }
  if (!std::is_sorted(boxes_.owner.begin(), boxes_.owner.end())) {
    const auto o = ownerOrder(boxes_.owner);
    for (auto* v : {&boxes_.cx, &boxes_.cy, &boxes_.cz, &boxes_.hx, &boxes_.hy, &boxes_.hz})
      permute(*v, o);
    for (auto& v : boxes_.r) permute(v, o);
    permute(boxes_.object, o);
    permute(boxes_.owner, o);
  }
  if (!std::is_sorted(cylinders_.owner.begin(), cylinders_.owner.end())) {
    const auto o = ownerOrder(cylinders_.owner);
    for (auto* v : {&cylinders_.cx, &cylinders_.cy, &cylinders_.cz, &cylinders_.ux, &cylinders_.uy,
                    &cylinders_.uz, &cylinders_.h, &cylinders_.r})
      permute(*v, o);
    permute(cylinders_.object, o);
    permute(cylinders_.owner, o);
  }

  // One group per distinct owner, ascending (no owner first): walk the four
  // sorted owner arrays together.
  groups_.clear();
  uint32_t si = 0, ci = 0, bi = 0, yi = 0;
  const auto ns = static_cast<uint32_t>(spheres_.owner.size());
  const auto nc = static_cast<uint32_t>(capsules_.owner.size());
  const auto nb = static_cast<uint32_t>(boxes_.owner.size());
  const auto ny = static_cast<uint32_t>(cylinders_.owner.size());
  constexpr int32_t kEnd = std::numeric_limits<int32_t>::max();
  while (si < ns || ci < nc || bi < nb || yi < ny) {
    const int32_t owner =
        std::min({si < ns ? spheres_.owner[si] : kEnd, ci < nc ? capsules_.owner[ci] : kEnd,
                  bi < nb ? boxes_.owner[bi] : kEnd, yi < ny ? cylinders_.owner[yi] : kEnd});
    Group g;
    g.owner = owner;
    g.sphere_begin = si;
    while (si < ns && spheres_.owner[si] == owner) ++si;
    g.sphere_end = si;
    g.capsule_begin = ci;
    while (ci < nc && capsules_.owner[ci] == owner) ++ci;
    g.capsule_end = ci;
    g.box_begin = bi;
    while (bi < nb && boxes_.owner[bi] == owner) ++bi;
    g.box_end = bi;
    g.cylinder_begin = yi;
    while (yi < ny && cylinders_.owner[yi] == owner) ++yi;
    g.cylinder_end = yi;

    // Bounding sphere around the primitives' own bounding spheres: centre at
    // their mean, radius to the farthest.
    auto each = [&](auto&& f) {
      for (uint32_t i = g.sphere_begin; i < g.sphere_end; ++i)
        f(Vec3f(spheres_.cx[i], spheres_.cy[i], spheres_.cz[i]), spheres_.r[i]);
      for (uint32_t i = g.capsule_begin; i < g.capsule_end; ++i) {
        const Vec3f a(capsules_.ax[i], capsules_.ay[i], capsules_.az[i]);
        const Vec3f b(capsules_.bx[i], capsules_.by[i], capsules_.bz[i]);
        f(0.5f * (a + b), 0.5f * (b - a).norm() + capsules_.r[i]);
      }
      for (uint32_t i = g.box_begin; i < g.box_end; ++i)
        f(Vec3f(boxes_.cx[i], boxes_.cy[i], boxes_.cz[i]),
          Vec3f(boxes_.hx[i], boxes_.hy[i], boxes_.hz[i]).norm());
      for (uint32_t i = g.cylinder_begin; i < g.cylinder_end; ++i)
        f(Vec3f(cylinders_.cx[i], cylinders_.cy[i], cylinders_.cz[i]),
          std::hypot(cylinders_.h[i], cylinders_.r[i]));
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
}

void RayScene::traceGroup(const Group& g, const Ray& ray, RayHit& hit, Best& best) const {
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
    take(raySphere(ox, oy, oz, dx, dy, dz, spheres_.cx[i], spheres_.cy[i], spheres_.cz[i],
                   spheres_.r[i]),
         spheres_.object[i], i);

  kind = Kind::Capsule;
  for (uint32_t i = g.capsule_begin; i < g.capsule_end; ++i) {
    const float ax = capsules_.ax[i], ay = capsules_.ay[i], az = capsules_.az[i];
    const float bx = capsules_.bx[i], by = capsules_.by[i], bz = capsules_.bz[i];
    const float r = capsules_.r[i];
    // Cylindrical body between the end caps.
    const float ux = bx - ax, uy = by - ay, uz = bz - az;
    const float px = ox - ax, py = oy - ay, pz = oz - az;
    const float uu = ux * ux + uy * uy + uz * uz;
    const float ud = ux * dx + uy * dy + uz * dz;
    const float up = ux * px + uy * py + uz * pz;
    const float dp = dx * px + dy * py + dz * pz;
    const float pp = px * px + py * py + pz * pz;
    float t = kInf;
    const float A = uu - ud * ud;
    if (A > kEps) {
      const float B = uu * dp - up * ud;
      const float C = uu * pp - up * up - r * r * uu;
      const float h = B * B - A * C;
      if (h >= 0.0f) {
        const float tb = (-B - std::sqrt(h)) / A;
        const float y = up + tb * ud;
        if (tb >= 0.0f && y > 0.0f && y < uu) t = tb;
      }
    }
    t = std::min({t, raySphere(ox, oy, oz, dx, dy, dz, ax, ay, az, r),
                  raySphere(ox, oy, oz, dx, dy, dz, bx, by, bz, r)});
    take(t, capsules_.object[i], i);
  }

  kind = Kind::Box;
  for (uint32_t i = g.box_begin; i < g.box_end; ++i) {
    // Ray in box coordinates: local = R^T (o - c), R^T d.
    const float px = ox - boxes_.cx[i], py = oy - boxes_.cy[i], pz = oz - boxes_.cz[i];
    const float* R[9];
    for (int k = 0; k < 9; ++k) R[k] = &boxes_.r[k][i];
    const float lo[3] = {*R[0] * px + *R[3] * py + *R[6] * pz, *R[1] * px + *R[4] * py + *R[7] * pz,
                         *R[2] * px + *R[5] * py + *R[8] * pz};
    const float ld[3] = {*R[0] * dx + *R[3] * dy + *R[6] * dz, *R[1] * dx + *R[4] * dy + *R[7] * dz,
                         *R[2] * dx + *R[5] * dy + *R[8] * dz};
    const float h[3] = {boxes_.hx[i], boxes_.hy[i], boxes_.hz[i]};
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
    const float ux = cylinders_.ux[i], uy = cylinders_.uy[i], uz = cylinders_.uz[i];
    const float hh = cylinders_.h[i], r = cylinders_.r[i];
    const float px = ox - cylinders_.cx[i], py = oy - cylinders_.cy[i], pz = oz - cylinders_.cz[i];
    const float oa = px * ux + py * uy + pz * uz;  // along the axis
    const float da = dx * ux + dy * uy + dz * uz;
    const float qx = px - oa * ux, qy = py - oa * uy, qz = pz - oa * uz;  // across
    const float ex = dx - da * ux, ey = dy - da * uy, ez = dz - da * uz;
    float t = kInf;
    const float a = ex * ex + ey * ey + ez * ez;
    const float b = qx * ex + qy * ey + qz * ez;
    const float c = qx * qx + qy * qy + qz * qz - r * r;
    if (a > kEps) {
      const float disc = b * b - a * c;
      if (disc >= 0.0f) {
        const float ts = (-b - std::sqrt(disc)) / a;
        if (ts >= 0.0f && std::abs(oa + ts * da) <= hh) t = ts;
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
  const uint32_t i = b.index;
  switch (b.kind) {
    case Kind::None:
      return Vec3f::Zero();
    case Kind::Ground:
      return Vec3f::UnitZ();
    case Kind::Sphere:
      return (p - Vec3f(spheres_.cx[i], spheres_.cy[i], spheres_.cz[i])).normalized();
    case Kind::Capsule: {
      const Vec3f a(capsules_.ax[i], capsules_.ay[i], capsules_.az[i]);
      const Vec3f u = Vec3f(capsules_.bx[i], capsules_.by[i], capsules_.bz[i]) - a;
      const float s = std::clamp((p - a).dot(u) / u.squaredNorm(), 0.0f, 1.0f);
      return (p - (a + s * u)).normalized();
    }
    case Kind::Box: {
      Mat3f r;
      for (int k = 0; k < 9; ++k) r(k / 3, k % 3) = boxes_.r[k][i];
      const Vec3f local = r.transpose() * (p - Vec3f(boxes_.cx[i], boxes_.cy[i], boxes_.cz[i]));
      const Vec3f h(boxes_.hx[i], boxes_.hy[i], boxes_.hz[i]);
      int axis = 0;
      (local.array().abs() / h.array()).maxCoeff(&axis);
      return r.col(axis) * (local[axis] < 0.0f ? -1.0f : 1.0f);
    }
    case Kind::Cylinder: {
      const Vec3f c(cylinders_.cx[i], cylinders_.cy[i], cylinders_.cz[i]);
      const Vec3f u(cylinders_.ux[i], cylinders_.uy[i], cylinders_.uz[i]);
      const float along = (p - c).dot(u);
      if (std::abs(along) >= cylinders_.h[i] - 1e-5f) return u * (along < 0.0f ? -1.0f : 1.0f);
      return (p - c - along * u).normalized();
    }
  }
  return Vec3f::Zero();
}

void RayScene::trace(std::span<const Ray> rays, std::span<RayHit> hits) const {
  for (size_t k = 0; k < rays.size(); ++k) {
    const Ray& ray = rays[k];
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
    for (const Group& g : groups_) {
      if (g.owner != kNoOwner && g.owner == ray.exclude_owner) continue;
      // Broadphase: skip the group unless the ray passes within its bounding
      // sphere before the best hit so far.
      const Vec3f oc = g.centre - ray.origin;
      const float along = std::clamp(oc.dot(ray.direction), 0.0f, hit.distance);
      if ((oc - along * ray.direction).squaredNorm() > g.radius * g.radius) continue;
      traceGroup(g, ray, hit, best);
    }
    if (hit.object == kNoObject)
      hit.distance = kInf;
    else
      hit.normal = normalAt(best, ray.origin + hit.distance * ray.direction);
    hits[k] = hit;
  }
}

}  // namespace simsoccer::engine

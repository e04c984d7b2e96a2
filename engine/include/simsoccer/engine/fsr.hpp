// Foot pressure: how one contact force on a sole is shared by four force
// sensors at the corners of a rectangle (FL, FR, RL, RR; front = +x,
// left = +y), by bilinear weights of the contact point's position. Points
// outside the rectangle go to its nearest edge.
#pragma once

#include <algorithm>
#include <array>

namespace simsoccer::engine {

struct FsrRectangle {
  double x_front = 0.0, x_rear = 0.0;  // mean x of the front / rear pair
  double y_left = 0.0, y_right = 0.0;  // mean y of the left / right pair
};

// Weights for FL, FR, RL, RR; they sum to 1.
inline std::array<double, 4> fsrWeights(const FsrRectangle& r, double x, double y) {
  const double u = std::clamp((x - r.x_rear) / (r.x_front - r.x_rear), 0.0, 1.0);   // 1 = front
  const double v = std::clamp((y - r.y_right) / (r.y_left - r.y_right), 0.0, 1.0);  // 1 = left
  return {u * v, u * (1 - v), (1 - u) * v, (1 - u) * (1 - v)};
}

}  // namespace simsoccer::engine

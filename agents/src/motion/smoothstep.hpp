// Shared by the motion engines (private to agents/).
#pragma once

#include <algorithm>

namespace simsoccer::agents {

// 0 at t <= 0, 1 at t >= 1, with zero slope at both ends: starts and stops
// without a jump in velocity.
inline double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace simsoccer::agents

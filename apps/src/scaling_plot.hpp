// bench scaling's plot (PNG): real-time factor and control frames per second
// against robots, log scale, beside USARSim's published 110, 55, 30, 10 fps
// for 1-4 Naos.
#pragma once

#include <filesystem>
#include <vector>

namespace simsoccer::apps {

struct ScalingPoint {
  int robots = 0;
  double fps = 0.0, rtf = 0.0;
};
void writeScalingPlot(const std::vector<ScalingPoint>& rows, const std::filesystem::path& file);

}  // namespace simsoccer::apps

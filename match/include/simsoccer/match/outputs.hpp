// What a run writes besides its log: the summary, the heatmap, the video
// rendered from the log, and the penalty kicks' statistics.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "simsoccer/match/match_runner.hpp"
#include "simsoccer/match/match_session.hpp"

namespace simsoccer::match {

// summary.json: teams, score, goals, referee events, penalties, per-robot
// falls and distance, possession, agent restarts, times, hashes. `extra`:
// more members, each line ending in ",\n".
void writeSummary(const std::filesystem::path& file, const MatchSession& s, const RunResult& r,
                  const RunOptions& o, const std::string& extra = "");

struct VideoResult {
  int frames = 0;
  std::filesystem::path file;
};
// Renders the spectator camera over the log's frames in [from, to] s at the
// video's rate, with the score and clock on top (.mp4, .avi; .png: one still
// at `from`).
VideoResult renderVideo(const std::filesystem::path& log_file, const std::filesystem::path& out,
                        const VideoSettings& v, double from, double to);
// Ball (white) and team (blue, red) positions over the game on a drawing of the field.
void writeHeatmap(const std::filesystem::path& log_file, const std::filesystem::path& out);

// A proportion with its 95 % confidence interval (Wilson score interval).
struct Proportion {
  double rate = 0.0, low = 0.0, high = 0.0;
};
Proportion wilsonInterval(int successes, int trials);

// A finite number with `decimals` decimals (0 for a NaN or an infinity: JSON
// has none), as the summary and the log header write numbers.
std::string fixedNumber(double v, int decimals = 3);

// A string as a JSON string literal.
std::string jsonString(const std::string& s);

}  // namespace simsoccer::match

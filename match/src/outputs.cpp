#include "simsoccer/match/outputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/world/render_scene.hpp"

namespace simsoccer::match {
std::string fixedNumber(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::isfinite(v) ? v : 0.0);
  return buf;
}

std::string jsonString(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
      continue;
    }
    o += c;
  }
  return o + "\"";
}

Proportion wilsonInterval(int successes, int trials) {
  const double n = std::max(trials, 1), p = trials ? static_cast<double>(successes) / n : 0.0;
  const double z = 1.96;
  const double denom = 1 + z * z / n;
  const double centre = (p + z * z / (2.0 * n)) / denom;
  const double half = z * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n)) / denom;
  return {p, std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

void writeSummary(const std::filesystem::path& file, const MatchSession& s, const RunResult& r,
                  const RunOptions& o, const std::string& extra) {
  const referee::Game& g = s.game();
  const world::World& w = s.world();
  std::ofstream out(file);
  if (!out) throw std::runtime_error(file.string() + ": cannot write the summary");
  out << "{\n";
  out << "  \"match\": " << jsonString(s.config().name) << ",\n";
  out << "  \"config\": " << jsonString(s.config().file) << ",\n";
  out << "  \"config_hash\": " << jsonString(s.config().hash) << ",\n";
  out << "  \"seed\": " << o.seed << ",\n";
  out << "  \"teams\": [";
  for (int t = 0; t < 2; ++t)
    out << (t ? ", " : "") << "{\"index\": " << t
        << ", \"number\": " << s.config().team_numbers[static_cast<size_t>(t)]
        << ", \"score\": " << g.score(t) << "}";
  out << "],\n";
  out << "  \"final_score\": [" << g.score(0) << ", " << g.score(1) << "],\n";
  out << "  \"winner\": " << (g.winner() ? std::to_string(*g.winner()) : "null") << ",\n";
  out << "  \"goals\": [";
  for (size_t i = 0; i < s.goals().size(); ++i) {
    const auto& goal = s.goals()[i];
    out << (i ? ", " : "") << "{\"time\": " << fixedNumber(goal.time, 2) << ", \"team\": " << goal.team
        << ", \"scorer\": " << goal.scorer
        << ", \"own_goal\": " << (goal.own_goal ? "true" : "false")
        << ", \"deflected_by\": " << goal.deflected_by << "}";
  }
  out << "],\n";
  out << "  \"referee_events\": [\n";
  for (size_t i = 0; i < r.events.size(); ++i) {
    const auto& e = r.events[i];
    out << "    {\"time\": " << fixedNumber(e.time, 2) << ", \"type\": " << jsonString(e.type)
        << ", \"team\": " << e.team << ", \"player\": " << e.player
        << ", \"detail\": " << jsonString(e.detail) << "}" << (i + 1 < r.events.size() ? "," : "")
        << "\n";
  }
  out << "  ],\n";
  out << "  \"penalties\": [";
  bool first = true;
  for (const auto& e : r.events)
    if (e.type == "penalty") {
      out << (first ? "" : ", ") << "{\"time\": " << fixedNumber(e.time, 2) << ", \"team\": " << e.team
          << ", \"player\": " << e.player << ", \"penalty\": " << jsonString(e.detail) << "}";
      first = false;
    }
  out << "],\n";
  out << "  \"robots\": [\n";
  for (size_t i = 0; i < s.robots().size(); ++i) {
    const auto& rec = s.robots()[i];
    out << "    {\"team\": " << rec.team << ", \"player\": " << rec.number
        << ", \"falls\": " << rec.falls.size() << ", \"get_ups\": "
        << std::count_if(rec.falls.begin(), rec.falls.end(),
                         [](const FallRecord& f) { return f.up_after.has_value(); })
        << ", \"keeper_dives\": " << rec.dives << ", \"ball_touches\": " << rec.touches
        << ", \"distance_walked\": " << fixedNumber(rec.distance, 2)
        << ", \"missed_commands\": " << (i < r.missed_commands.size() ? r.missed_commands[i] : 0)
        << ", \"fall_records\": [";
    for (size_t k = 0; k < rec.falls.size(); ++k) {
      const FallRecord& f = rec.falls[k];
      out << (k ? ", " : "") << "{\"time\": " << fixedNumber(f.time, 2) << ", \"x\": " << fixedNumber(f.x, 2)
          << ", \"y\": " << fixedNumber(f.y, 2) << ", \"nearest_robot\": "
          << (f.nearest_robot ? fixedNumber(*f.nearest_robot, 2) : std::string("null"))
          << ", \"ball\": " << fixedNumber(f.ball, 2)
          << ", \"up_after\": " << (f.up_after ? fixedNumber(*f.up_after, 2) : std::string("null")) << "}";
    }
    out << "]}" << (i + 1 < s.robots().size() ? "," : "") << "\n";
  }
  out << "  ],\n";
  const auto p = s.possession();
  out << "  \"possession\": [" << fixedNumber(p[0], 3) << ", " << fixedNumber(p[1], 3) << "],\n";
  out << "  \"agent_restarts\": [";
  for (size_t i = 0; i < r.agent_events.size(); ++i) out << (i ? ", " : "") << r.agent_events[i];
  out << "],\n";
  // LoLA robots: the socket and every fault their clients made (the robot held its last command).
  out << "  \"lola\": [";
  for (size_t i = 0; i < r.lola.size(); ++i) {
    const LolaResult& l = r.lola[i];
    const lola::RobotLolaStats& st = l.stats;
    out << (i ? "," : "") << "\n    {\"team\": " << l.player.team_number
        << ", \"player\": " << l.player.player << ", \"socket\": " << jsonString(l.socket.string())
        << ", \"address\": " << (l.address.empty() ? "null" : jsonString(l.address))
        << ", \"sessions\": " << st.sessions << ", \"packets_sent\": " << st.packets_sent
        << ", \"packets_dropped\": " << st.packets_dropped << ", \"answered\": " << st.answered
        << ", \"missed\": " << st.missed << ", \"no_client\": " << st.no_client
        << ", \"maps\": " << st.maps << ", \"bad_maps\": " << st.bad_maps
        << ", \"unknown_keys\": " << st.unknown_keys << ", \"stream_errors\": " << st.stream_errors
        << ", \"refused_commands\": " << st.refused << ", \"bytes_received\": " << st.bytes_received
        << "}";
  }
  out << (r.lola.empty() ? "" : "\n  ") << "],\n";
  out << "  \"control_period\": " << fixedNumber(w.scenario().physics.control_period, 3) << ",\n";
  if (!extra.empty()) out << extra;
  out << "  \"interrupted\": " << (r.interrupted ? "true" : "false") << ",\n";
  out << "  \"aborted\": " << (r.aborted ? jsonString(r.abort_reason) : "null") << ",\n";
  out << "  \"simulated_seconds\": " << fixedNumber(w.time(), 2) << ",\n";
  out << "  \"wall_seconds\": " << fixedNumber(r.wall, 2) << ",\n";
  out << "  \"longest_wait_seconds\": " << fixedNumber(r.longest_wait, 3) << ",\n";
  out << "  \"real_time_factor\": " << fixedNumber(w.time() / std::max(r.wall, 1e-9), 3) << ",\n";
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(r.final_hash));
  out << "  \"final_state_hash\": \"" << hash << "\",\n";
  out << "  \"log_frames\": " << r.frames << "\n";
  out << "}\n";
}

VideoResult renderVideo(const std::filesystem::path& log_file, const std::filesystem::path& out,
                        const VideoSettings& v, double from, double to) {
  world::MatchLogReader log(log_file);
  const auto& h = log.header().values;
  if (!h.count("scenario"))
    throw std::runtime_error(log_file.string() + ": no scenario in the header");
  world::World w(world::loadScenario(h.at("scenario")));
  engine::OffscreenRenderer renderer;
  const double vfov = 2 * std::atan(std::tan(0.5 * v.horizontal_fov) * v.height / v.width);
  const engine::RenderView view = engine::pinholeView(world::lookAtPose(v.position, v.look_at),
                                                      v.width, v.height, v.horizontal_fov, vfov);
  VideoResult result;
  result.file = out;
  cv::VideoWriter writer;
  const bool png = out.extension() == ".png";  // one still: the first frame at `from`
  const bool avi = out.extension() == ".avi";
  if (!png) {
    writer.open(
        out.string(),
        cv::VideoWriter::fourcc(avi ? 'M' : 'm', avi ? 'J' : 'p', avi ? 'P' : '4', avi ? 'G' : 'v'),
        v.fps, cv::Size(v.width, v.height));
    if (!writer.isOpened())
      throw std::runtime_error(out.string() + ": OpenCV cannot write this video");
  }
  world::LogFrame f;
  double next = -1.0;
  std::vector<engine::DrawItem> scene;
  world::SceneColours colours;
  while (log.next(f)) {
    if (f.time < from - 1e-9) continue;
    if (f.time > to + 1e-9) break;
    if (next >= 0 && f.time < next - 1e-9) continue;
    next = (next < 0 ? f.time : next) + 1.0 / v.fps;
    world::applyFrame(w, f);
    scene.clear();
    colours.leds.assign(f.robots.size(), std::nullopt);
    for (size_t r = 0; r < f.robots.size(); ++r)
      if (const auto& l = f.robots[r].leds) {
        const auto rgb = [&](size_t k) {
          return Eigen::Vector3f((*l)[k] / 255.0f, (*l)[k + 1] / 255.0f, (*l)[k + 2] / 255.0f);
        };
        colours.leds[r] = world::SceneColours::Leds{rgb(0), rgb(3), rgb(6)};
      }
    world::buildRenderScene(w, scene, colours);
    renderer.render(scene, std::span<const engine::RenderView>(&view, 1));
    cv::Mat rgba = renderer.image(0), bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    // Overlay: score, game clock and state from the frame's GameController packet.
    std::string text = "t " + fixedNumber(f.time, 1) + " s";
    if (f.game.size() == referee::kControlSize) {
      const referee::ControlData d = referee::decodeControl(f.game);
      char buf[160];
      std::snprintf(buf, sizeof buf, "%d  %d : %d  %d   %s %02d:%02d  %s", d.teams[0].team_number,
                    d.teams[0].score, d.teams[1].score, d.teams[1].team_number,
                    d.first_half ? "1st" : "2nd", std::max(0, (int)d.secs_remaining) / 60,
                    std::max(0, (int)d.secs_remaining) % 60,
                    referee::stateName(static_cast<referee::gc::State>(d.state)));
      text = buf;
    }
    cv::rectangle(bgr, cv::Point(0, 0), cv::Point(v.width, 26), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(bgr, text, cv::Point(8, 19), cv::FONT_HERSHEY_SIMPLEX, 0.55,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    ++result.frames;
    if (png) {
      if (!cv::imwrite(out.string(), bgr))
        throw std::runtime_error(out.string() + ": cannot write");
      break;
    }
    writer.write(bgr);
  }
  return result;
}

void writeHeatmap(const std::filesystem::path& log_file, const std::filesystem::path& out) {
  world::MatchLogReader log(log_file);
  const fields::FieldModel f =
      fields::loadFieldModel(world::loadScenario(log.header().values.at("scenario")).field_file);
  const double ppm = 60.0, margin = f.border;
  const int W = static_cast<int>((f.length + 2 * margin) * ppm),
            H = static_cast<int>((f.width + 2 * margin) * ppm);
  auto px = [&](double x, double y) {
    return cv::Point2d((x + f.halfLength() + margin) * ppm, (f.halfWidth() + margin - y) * ppm);
  };
  std::array<cv::Mat, 3> density;
  for (auto& d : density) d = cv::Mat::zeros(H, W, CV_32F);
  world::LogFrame fr;
  const auto& robots = log.header().robots;
  while (log.next(fr)) {
    auto add = [&](cv::Mat& m, double x, double y) {
      const cv::Point2d p = px(x, y);
      if (p.x >= 0 && p.y >= 0 && p.x < W && p.y < H)
        m.at<float>(static_cast<int>(p.y), static_cast<int>(p.x)) += 1.0f;
    };
    add(density[2], fr.ball.translation().x(), fr.ball.translation().y());
    for (size_t r = 0; r < fr.robots.size() && r < robots.size(); ++r)
      add(density[static_cast<size_t>(std::clamp(robots[r].team, 0, 1))],
          fr.robots[r].torso.translation().x(), fr.robots[r].torso.translation().y());
  }
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(40, 120, 30));
  for (const auto& l : f.lines)
    cv::line(img, px(l.a.x(), l.a.y()), px(l.b.x(), l.b.y()), cv::Scalar(255, 255, 255), 2,
             cv::LINE_AA);
  for (const auto& c : f.circles)
    cv::circle(img, px(c.centre.x(), c.centre.y()), static_cast<int>(c.radius * ppm),
               cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  const cv::Scalar colours[3] = {cv::Scalar(255, 80, 30), cv::Scalar(30, 40, 240),
                                 cv::Scalar(255, 255, 255)};
  for (size_t k = 0; k < 3; ++k) {
    cv::Mat blurred;
    cv::GaussianBlur(density[k], blurred, cv::Size(0, 0), 0.25 * ppm);
    double maxv = 0;
    cv::minMaxLoc(blurred, nullptr, &maxv);
    if (maxv <= 0) continue;
    cv::Mat alpha;
    cv::sqrt(blurred / maxv, alpha);  // square root: the rarely visited places still show
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float a = 0.8f * alpha.at<float>(y, x);
        cv::Vec3b& p = img.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) p[c] = static_cast<uint8_t>((1 - a) * p[c] + a * colours[k][c]);
      }
  }
  cv::putText(img, "team 0", cv::Point(10, 24), cv::FONT_HERSHEY_SIMPLEX, 0.7, colours[0], 2);
  cv::putText(img, "team 1", cv::Point(110, 24), cv::FONT_HERSHEY_SIMPLEX, 0.7, colours[1], 2);
  cv::putText(img, "ball", cv::Point(210, 24), cv::FONT_HERSHEY_SIMPLEX, 0.7, colours[2], 2);
  if (!cv::imwrite(out.string(), img))
    throw std::runtime_error(out.string() + ": cannot write the heatmap");
}

}  // namespace simsoccer::match

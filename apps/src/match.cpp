// simsoccer match / penalty / replay: the main job. A match runs the whole
// game in lockstep with one agent process per robot, records a match log,
// and writes the summary, a heatmap and a video rendered from the log.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <thread>

#include "cli.hpp"
#include "match_session.hpp"
#include "process.hpp"
#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/sim/log_source.hpp"
#include "simsoccer/sim/run_loop.hpp"
#include "simsoccer/world/render_scene.hpp"

namespace simsoccer::apps {
namespace {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_interrupted = 0;
void onInterrupt(int) {
  g_interrupted = 1;
}

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
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

std::string num(double v, int decimals = 3) {
  return fmt(std::isfinite(v) ? v : 0.0, decimals);
}

std::filesystem::path defaultOut() {
  char buf[32];
  const std::time_t t = std::time(nullptr);
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&t));
  return std::filesystem::path("runs") / buf;
}

// Makes the output folder and proves it is writable, before anything runs.
void prepareOut(const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec)
    throw std::runtime_error(out.string() + ": cannot create the output folder (" + ec.message() +
                             ")");
  const auto probe = out / ".write_test";
  std::ofstream f(probe);
  if (!f) throw std::runtime_error(out.string() + ": the output folder is not writable");
  f.close();
  std::filesystem::remove(probe, ec);
}

// --- video and heatmap from the log ---------------------------------------------------------

struct VideoResult {
  int frames = 0;
  std::filesystem::path file;
};

// Renders the spectator camera over the log's frames in [from, to] s at the
// video's rate, with the score and clock on top.
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
  while (log.next(f)) {
    if (f.time < from - 1e-9) continue;
    if (f.time > to + 1e-9) break;
    if (next >= 0 && f.time < next - 1e-9) continue;
    next = (next < 0 ? f.time : next) + 1.0 / v.fps;
    world::applyFrame(w, f);
    scene.clear();
    world::buildRenderScene(w, scene);
    renderer.render(scene, std::span<const engine::RenderView>(&view, 1));
    cv::Mat rgba = renderer.image(0), bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    // Overlay: score, game clock and state from the frame's GameController packet.
    std::string text = "t " + fmt(f.time, 1) + " s";
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

// Ball (white) and team (blue, red) positions over the game on a drawing of the field.
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

// --- the live run -----------------------------------------------------------------------------

struct AgentSlot {
  int team = 0, number = 0;
  std::unique_ptr<ChildProcess> process;
  int restarts = 0;
};

struct RunOptions {
  std::filesystem::path out;
  uint64_t seed = 1;
  bool realtime = false, external = false, video = true, quiet = false;
  uint32_t domain = 0;
  std::filesystem::path dds_config;  // the simulator's and the agents' Cyclone configuration
  double max_seconds = 0.0;          // > 0: stop after this much simulated time
  sim::Mode mode = sim::Mode::Serial;  // of the control period
};

struct RunResult {
  bool interrupted = false, aborted = false;
  std::string abort_reason;
  double wall = 0.0;
  uint64_t final_hash = 0;
  std::vector<std::string> agent_events;  // restarts
  // Per robot (world order): lockstep periods its agent did not answer within
  // the timeout (the robot kept its last command: a cause for a changed game).
  std::vector<uint64_t> missed_commands;
  std::vector<world::LogEvent> events;
  int frames = 0;
  uint64_t log_bytes = 0;
};

// Stage record: each period into the match log (poses, joints, ball, the
// commands applied, the game packet, the referee's events, the state hash).
class LogRecorder : public sim::Recorder {
 public:
  LogRecorder(world::MatchLogWriter& log, RunResult& result) : log_(log), result_(result) {}
  void record(const sim::PeriodRecord& p) override {
    const world::World& w = *p.world;
    positions_.resize(w.robotCount());
    stiffness_.resize(w.robotCount());
    commanded_.assign(p.commanded->begin(), p.commanded->end());
    for (world::RobotId r = 0; r < w.robotCount(); ++r) {
      positions_[r] = (*p.commands)[r].position;
      stiffness_[r] = (*p.commands)[r].stiffness;
    }
    world::LogFrame frame = world::captureFrame(w, w.controlTick(), positions_, stiffness_, commanded_);
    if (p.game) {
      const auto packet = referee::encode(*p.game);
      frame.game.assign(packet.begin(), packet.end());
    }
    for (const sim::Event& e : *p.events) {
      const world::LogEvent le{e.time, referee::eventName(e.type), e.team, e.player, e.detail};
      result_.events.push_back(le);
      frame.events.push_back(le);
    }
    log_.write(frame);
    ++result_.frames;
  }

 private:
  world::MatchLogWriter& log_;
  RunResult& result_;
  std::vector<std::array<double, 25>> positions_, stiffness_;
  std::vector<bool> commanded_;
};

// Plays one session (a game, or one penalty kick) with agents, logging to `log`.
RunResult play(MatchSession& session, const RunOptions& o, world::MatchLogWriter& log) {
  RunResult result;
  world::World& w = session.world();
  const MatchConfig& c = session.config();
  sim::SimulationConfig simc;
  simc.mode = o.mode;
  simc.lockstep = !o.realtime;
  sim::Simulation simulation(w, simc);
  session.attach(simulation);
  LogRecorder recorder(log, result);
  simulation.addRecorder(recorder);
  net::ServerConfig sc;
  sc.dds.domain = o.domain;
  sc.dds.config_file = o.dds_config;
  sc.lockstep = !o.realtime;
  sc.command_timeout = c.command_timeout;
  sc.team_message_delay = c.message_delay;
  sc.team_message_loss = c.message_loss;
  net::SimServer server(simulation, sc);
  // The agents find the game state when they start.
  server.publishGameState(session.controlData(), session.game().leftTeam());
  auto agentCommand = [&](int team, int number) {  // the same for a restart
    SoccerAgentOptions ao;
    ao.team = team;
    ao.player = number;
    ao.domain = o.domain;
    ao.dds_config = o.dds_config;
    ao.role = c.role;
    ao.field = w.scenario().field_file;
    ao.config = c.agent_config;
    ao.team_number = c.team_numbers[static_cast<size_t>(team)];
    ao.seed = o.seed * 1000 + static_cast<uint64_t>(team * 100 + number);
    ao.get_up = c.get_up;
    return soccerAgentCommand(ao);
  };
  std::vector<AgentSlot> agents;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    AgentSlot a;
    a.team = w.robot(r).team;
    a.number = w.robot(r).number;
    if (!o.external) {
      a.process = std::make_unique<ChildProcess>(agentCommand(a.team, a.number));
      if (!a.process->started())
        throw std::runtime_error("cannot start " + agentProgram().string());
    }
    agents.push_back(std::move(a));
  }
  const auto t_wait = Clock::now();
  while (!g_interrupted && !server.waitForOwners(w.robotCount(), 0.5)) {
    if (secondsSince(t_wait) > 60.0)
      throw std::runtime_error("agents did not claim their robots within 60 s");
  }
  const auto t0 = Clock::now();
  double last_status = -1.0;
  const bool tty = !o.quiet && isatty(STDOUT_FILENO);
  long i = 0;
  // Agents that died are restarted (up to the limit); past it the match stops.
  const auto superviseAgents = [&] {
    for (AgentSlot& a : agents) {
      if (a.process->running()) continue;
      char buf[200];
      if (a.restarts >= c.restart_limit) {
        result.aborted = true;
        std::snprintf(buf, sizeof buf, "agent of team %d player %d exited %d times (limit %d)",
                      a.team, a.number, a.restarts + 1, c.restart_limit);
        result.abort_reason = buf;
        return;
      }
      ++a.restarts;
      // Its robot is free at once: a crashed process says nothing on DDS, and
      // lockstep would wait for it every period until its lease ran out. (Not
      // when it exited 3, not granted: then another participant owns it.)
      if (a.process->exitStatus() != 3)
        for (world::RobotId r = 0; r < w.robotCount(); ++r)
          if (w.robot(r).team == a.team && w.robot(r).number == a.number) server.releaseRobot(r);
      std::snprintf(buf, sizeof buf,
                    "{\"time\": %s, \"team\": %d, \"player\": %d, \"exit_status\": %d, "
                    "\"restart\": %d}",
                    num(w.time(), 2).c_str(), a.team, a.number, a.process->exitStatus(),
                    a.restarts);
      result.agent_events.push_back(buf);
      a.process = std::make_unique<ChildProcess>(agentCommand(a.team, a.number));
    }
  };
  const auto status = [&] {
    last_status = secondsSince(t0);
    const auto& g = session.game();
    const double rtf = w.time() / std::max(1e-6, secondsSince(t0));
    const double half = g.rules().half_duration;
    const double left_sim =
        std::max(0.0, g.secondsRemaining() + (g.half() == referee::Half::First ? half : 0.0));
    std::printf("\r  %s half  %02d:%02d  %-8s  %d:%d   sim %6.1f s  RTF %4.2f  ETA %4.0f s   ",
                g.half() == referee::Half::First
                    ? "1st"
                    : (g.half() == referee::Half::Second ? "2nd" : "pso"),
                static_cast<int>(g.secondsRemaining()) / 60,
                static_cast<int>(g.secondsRemaining()) % 60, referee::stateName(g.state()),
                g.score(0), g.score(1), w.time(), rtf, left_sim / std::max(rtf, 1e-3));
    std::fflush(stdout);
  };
  sim::RunLoop loop(simulation, o.realtime ? sim::Pacing::RealTime : sim::Pacing::Lockstep);
  loop.run(
      [&] {
        return session.over() || g_interrupted || result.aborted ||
               (o.max_seconds > 0 && w.time() >= o.max_seconds - 1e-9);
      },
      -1,
      [&] {
        ++i;
        if (!o.external && i % 10 == 0) superviseAgents();
        if (tty && secondsSince(t0) - last_status > 0.25) status();
      });
  if (tty) std::printf("\n");
  result.interrupted = g_interrupted != 0;
  result.wall = secondsSince(t0);
  result.final_hash = w.stateHash();
  for (world::RobotId r = 0; r < w.robotCount(); ++r)
    result.missed_commands.push_back(server.stats(r).missed);
  for (AgentSlot& a : agents)
    if (a.process) a.process->stop();
  log.flush();
  return result;
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
    out << (i ? ", " : "") << "{\"time\": " << num(goal.time, 2) << ", \"team\": " << goal.team
        << ", \"scorer\": " << goal.scorer
        << ", \"own_goal\": " << (goal.own_goal ? "true" : "false") << "}";
  }
  out << "],\n";
  out << "  \"referee_events\": [\n";
  for (size_t i = 0; i < r.events.size(); ++i) {
    const auto& e = r.events[i];
    out << "    {\"time\": " << num(e.time, 2) << ", \"type\": " << jsonString(e.type)
        << ", \"team\": " << e.team << ", \"player\": " << e.player
        << ", \"detail\": " << jsonString(e.detail) << "}" << (i + 1 < r.events.size() ? "," : "")
        << "\n";
  }
  out << "  ],\n";
  out << "  \"penalties\": [";
  bool first = true;
  for (const auto& e : r.events)
    if (e.type == "penalty") {
      out << (first ? "" : ", ") << "{\"time\": " << num(e.time, 2) << ", \"team\": " << e.team
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
        << ", \"keeper_dives\": " << rec.dives << ", \"distance_walked\": " << num(rec.distance, 2)
        << ", \"missed_commands\": " << (i < r.missed_commands.size() ? r.missed_commands[i] : 0)
        << ", \"fall_records\": [";
    for (size_t k = 0; k < rec.falls.size(); ++k) {
      const FallRecord& f = rec.falls[k];
      out << (k ? ", " : "") << "{\"time\": " << num(f.time, 2) << ", \"x\": " << num(f.x, 2)
          << ", \"y\": " << num(f.y, 2) << ", \"nearest_robot\": "
          << (f.nearest_robot ? num(*f.nearest_robot, 2) : std::string("null"))
          << ", \"ball\": " << num(f.ball, 2)
          << ", \"up_after\": " << (f.up_after ? num(*f.up_after, 2) : std::string("null")) << "}";
    }
    out << "]}" << (i + 1 < s.robots().size() ? "," : "") << "\n";
  }
  out << "  ],\n";
  const auto p = s.possession();
  out << "  \"possession\": [" << num(p[0], 3) << ", " << num(p[1], 3) << "],\n";
  out << "  \"agent_restarts\": [";
  for (size_t i = 0; i < r.agent_events.size(); ++i) out << (i ? ", " : "") << r.agent_events[i];
  out << "],\n";
  if (!extra.empty()) out << extra;
  out << "  \"interrupted\": " << (r.interrupted ? "true" : "false") << ",\n";
  out << "  \"aborted\": " << (r.aborted ? jsonString(r.abort_reason) : "null") << ",\n";
  out << "  \"simulated_seconds\": " << num(w.time(), 2) << ",\n";
  out << "  \"wall_seconds\": " << num(r.wall, 2) << ",\n";
  out << "  \"real_time_factor\": " << num(w.time() / std::max(r.wall, 1e-9), 3) << ",\n";
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(r.final_hash));
  out << "  \"final_state_hash\": \"" << hash << "\",\n";
  out << "  \"log_frames\": " << r.frames << "\n";
  out << "}\n";
}

world::MatchLogHeader logHeader(const MatchSession& s, const RunOptions& o) {
  world::MatchLogHeader h;
  const world::World& w = s.world();
  h.values["config"] = std::filesystem::absolute(s.config().file).string();
  h.values["config_hash"] = s.config().hash;
  h.values["scenario"] = std::filesystem::absolute(s.config().scenario).string();
  h.values["seed"] = std::to_string(o.seed);
  h.values["control_period"] = fmt(w.scenario().physics.control_period, 6);
  if (s.config().half_duration) h.values["half_duration"] = fmt(*s.config().half_duration, 3);
  for (world::RobotId r = 0; r < w.robotCount(); ++r)
    h.robots.push_back({w.robot(r).team, w.robot(r).number,
                        static_cast<int>(w.robot(r).model->body->joints.size())});
  return h;
}

const char* kMatchHelp =
    "usage: simsoccer match CONFIG [--out DIR] [--seed N] [--realtime] [--external-agents]\n"
    "                       [--no-video] [--half S] [--max-seconds S] [--domain D]\n"
    "                       [--dds-config FILE] [--quiet]\n"
    "\n"
    "Plays a whole game (configs/match_5v5.yaml, match_7v7.yaml, match_11v11.yaml): the\n"
    "simulator, the automatic referee (halves, half-time, goals, set plays, penalties, a\n"
    "shoot-out if the rule book calls for it) and one simsoccer-agent process per robot over\n"
    "DDS, in lockstep (--realtime: paced to the wall clock). Agents that exit are restarted\n"
    "(agents.restart_limit times each); past that the match stops. Ctrl-C stops it too; what\n"
    "was recorded is kept. Writes to DIR (default runs/<date-time>/):\n"
    "  summary.json  teams, score, goals (time, scorer), referee events, penalties, falls,\n"
    "                shoot-out keeper dives (down once the shot is kicked: not falls) and\n"
    "                distance walked per robot, possession, agent restarts, simulated and\n"
    "                wall time, real-time factor, seed, config hash, final state hash\n"
    "  match.log     every control period (poses, joints, ball, game state, commands, state\n"
    "                hash) and the referee events; `simsoccer replay` reads it\n"
    "  match.mp4     the spectator camera rendered from the log, score and clock on top\n"
    "  heatmap.png   ball and team positions over the game\n"
    "  --half S            half duration in s (overrides the config)\n"
    "  --max-seconds S     stop after S simulated seconds (a partial game, for trials)\n"
    "  --lockstep-timeout S  wall seconds a period waits for the agents (overrides the\n"
    "                config's lockstep.timeout; a missed answer changes the game, and\n"
    "                summary.json counts them per robot: raise it on a loaded machine)\n"
    "  --domain D          DDS domain id (default 0): one per match running side by side\n"
    "  --external-agents   start no agents: wait for agents started elsewhere (same domain)\n"
    "  --dds-config FILE   Cyclone DDS configuration of the simulator and its agents (default\n"
    "                configs/dds/loopback.xml; configs/dds/lan.xml for agents on other machines)\n"
    "  --no-video          skip the video\n"
    "  --quiet             no live status line (it is also off when stdout is not a terminal)\n";

const char* kPenaltyHelp =
    "usage: simsoccer penalty CONFIG [--kicks N] [--out DIR] [--seed N] [--video-kicks K]\n"
    "                         [--domain D] [--dds-config FILE]\n"
    "\n"
    "Penalty kicks (configs/penalty.yaml): per kick a fresh world seeded SEED+k, the ball on\n"
    "the penalty mark, a striker and a goalkeeper agent (simsoccer-agent --role auto, which\n"
    "plays the penalty roles in the shoot-out phase), the shoot-out rules of the referee\n"
    "(30 s per kick, the keeper on its line until the kick). Prints and writes the scoring\n"
    "rate with a 95 % confidence interval (Wilson) and each kick's outcome (goal / saved /\n"
    "missed / timeout) to DIR/penalty.json, and a video of the first K kicks (default 3).\n"
    "  --domain D          DDS domain id (default 0)\n"
    "  --dds-config FILE   Cyclone DDS configuration of the simulator and its agents (default\n"
    "                      configs/dds/loopback.xml)\n";

const char* kReplayHelp =
    "usage: simsoccer replay LOG [--video FILE] [--from T] [--to T] [--physics [--threads N]]\n"
    "                            [--events]\n"
    "\n"
    "Reads a match log: prints what it holds (--events: every referee event); --video renders the "
    "spectator camera over\n"
    "[--from, --to] s (default the whole log) to FILE (.mp4 or .avi; .png: one still at\n"
    "--from); --physics re-runs the\n"
    "game through the physics and the referee with the recorded commands and checks every\n"
    "period's state hash against the log (exit status 1 on the first difference); --threads:\n"
    "with N solver threads instead of the scenario's (the hashes must not change).\n";

RunOptions runOptions(const Options& opt, const MatchConfig& c) {
  RunOptions o;
  o.out = opt.has("out") ? std::filesystem::path(opt.get("out", "")) : defaultOut();
  o.seed = static_cast<uint64_t>(opt.number("seed", static_cast<double>(c.seed)));
  o.domain = static_cast<uint32_t>(opt.number("domain", 0));
  o.dds_config = findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
  if (!std::filesystem::is_regular_file(o.dds_config))
    throw UsageError(opt.has("dds-config")
                         ? "--dds-config " + o.dds_config.string() + ": no such file"
                         : "the default DDS configuration " + o.dds_config.string() +
                               " is missing (give one with --dds-config)");
  o.quiet = opt.flag("quiet");
  return o;
}

}  // namespace

int match(int argc, char** argv, int first) {
  const Options opt(
      argc, argv, first, {"help", "realtime", "external-agents", "no-video", "quiet"},
      {"out", "seed", "half", "domain", "dds-config", "max-seconds", "lockstep-timeout"});
  if (opt.help(kMatchHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one match config file");
  MatchConfig config = loadMatchConfig(opt.positional()[0]);
  if (config.penalty_kicks > 0)
    throw UsageError(config.file + " is a penalty config: use `simsoccer penalty`");
  if (opt.has("half")) {
    const double h = opt.number("half", 0);
    if (!(h > 0)) throw UsageError("--half must be > 0 s");
    config.half_duration = h;
  }
  if (opt.has("lockstep-timeout")) {
    const double t = opt.number("lockstep-timeout", 0);
    if (!(t > 0)) throw UsageError("--lockstep-timeout must be > 0 s");
    config.command_timeout = t;
  }
  RunOptions o = runOptions(opt, config);
  o.realtime = opt.flag("realtime");
  o.external = opt.flag("external-agents");
  o.video = config.video.enabled && !opt.flag("no-video");
  o.max_seconds = opt.number("max-seconds", 0);
  prepareOut(o.out);

  MatchSession session(config, o.seed);
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  std::printf("simsoccer match %s: %zu robots, seed %llu, %s, output %s\n", config.name.c_str(),
              session.world().robotCount(), static_cast<unsigned long long>(o.seed),
              o.realtime ? "real time" : "lockstep", o.out.string().c_str());
  std::fflush(stdout);
  const auto log_file = o.out / "match.log";
  RunResult r;
  {
    world::MatchLogWriter log(log_file, logHeader(session, o));
    r = play(session, o, log);
    r.log_bytes = log.bytes();
  }
  writeSummary(o.out / "summary.json", session, r, o, "");
  const auto& g = session.game();
  std::printf("%s: %d:%d after %.1f simulated s in %.1f s (real-time factor %.2f); log %.1f MB\n",
              r.interrupted ? "interrupted" : (r.aborted ? "stopped" : "final"), g.score(0),
              g.score(1), session.world().time(), r.wall,
              session.world().time() / std::max(r.wall, 1e-9),
              static_cast<double>(r.log_bytes) / 1e6);
  if (r.aborted) std::printf("stopped: %s\n", r.abort_reason.c_str());
  for (const auto& goal : session.goals())
    std::printf("  goal %7.1f s  team %d  player %d%s\n", goal.time, goal.team, goal.scorer,
                goal.own_goal ? " (own goal)" : "");
  if (!r.interrupted) {
    writeHeatmap(log_file, o.out / "heatmap.png");
    if (o.video) {
      const VideoResult v = renderVideo(log_file, o.out / "match.mp4", config.video, 0, 1e12);
      std::printf("video: %s, %d frames\n", v.file.string().c_str(), v.frames);
    }
  }
  std::printf("wrote %s\n", (o.out / "summary.json").string().c_str());
  return r.aborted ? 3 : (r.interrupted ? 130 : 0);
}

int penalty(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "quiet"},
                    {"kicks", "out", "seed", "video-kicks", "domain", "dds-config"});
  if (opt.help(kPenaltyHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one penalty config file");
  MatchConfig config = loadMatchConfig(opt.positional()[0]);
  if (config.penalty_kicks == 0)
    throw UsageError(config.file + " is not a penalty config (`penalty: NAME`)");
  const int kicks = static_cast<int>(opt.number("kicks", config.penalty_kicks));
  if (kicks < 1) throw UsageError("--kicks must be >= 1");
  const int video_kicks = static_cast<int>(opt.number("video-kicks", 3));
  RunOptions o = runOptions(opt, config);
  o.quiet = true;
  prepareOut(o.out);
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  std::map<std::string, int> counts;
  std::vector<std::string> outcomes;
  std::vector<std::filesystem::path> logs;
  const uint64_t base = o.seed;
  for (int k = 0; k < kicks && !g_interrupted; ++k) {
    RunOptions ko = o;
    ko.seed = base + static_cast<uint64_t>(k);
    MatchSession session(config, ko.seed);
    const auto log_file = o.out / ("kick_" + std::to_string(k + 1) + ".log");
    {
      world::MatchLogWriter log(log_file, logHeader(session, ko));
      play(session, ko, log);
    }
    const auto& shots = session.game().shotOutcomes(0);
    std::string outcome = "timeout";
    if (!shots.empty()) {
      switch (shots[0]) {
        case referee::ShotOutcome::Goal:
          outcome = "goal";
          break;
        case referee::ShotOutcome::Saved:
          outcome = "saved";
          break;
        case referee::ShotOutcome::NoKick:
          outcome = "timeout";
          break;
        default:
          outcome = "missed";
          break;
      }
    }
    ++counts[outcome];
    outcomes.push_back(outcome);
    std::printf("  kick %2d (seed %llu): %s\n", k + 1, static_cast<unsigned long long>(ko.seed),
                outcome.c_str());
    std::fflush(stdout);
    if (k < video_kicks)
      logs.push_back(log_file);
    else
      std::filesystem::remove(log_file);
  }
  const int n = static_cast<int>(outcomes.size());
  const double goals = counts["goal"], p = n ? goals / n : 0.0, z = 1.96;
  // Wilson score interval.
  const double denom = 1 + z * z / std::max(n, 1);
  const double centre = (p + z * z / (2.0 * std::max(n, 1))) / denom;
  const double half =
      z *
      std::sqrt(p * (1 - p) / std::max(n, 1) + z * z / (4.0 * std::max(n, 1) * std::max(n, 1))) /
      denom;
  std::printf(
      "penalties: %d kicks, %d goals: scoring rate %.2f (95%% CI %.2f..%.2f); saved %d, missed %d, "
      "timeout %d\n",
      n, counts["goal"], p, std::max(0.0, centre - half), std::min(1.0, centre + half),
      counts["saved"], counts["missed"], counts["timeout"]);
  std::ofstream out(o.out / "penalty.json");
  out << "{\n  \"config\": " << jsonString(config.file) << ",\n  \"seed\": " << base
      << ",\n  \"kicks\": " << n << ",\n  \"scoring_rate\": " << num(p) << ",\n  \"ci95\": ["
      << num(std::max(0.0, centre - half)) << ", " << num(std::min(1.0, centre + half))
      << "],\n  \"counts\": {\"goal\": " << counts["goal"] << ", \"saved\": " << counts["saved"]
      << ", \"missed\": " << counts["missed"] << ", \"timeout\": " << counts["timeout"]
      << "},\n  \"outcomes\": [";
  for (size_t i = 0; i < outcomes.size(); ++i) out << (i ? ", " : "") << jsonString(outcomes[i]);
  out << "]\n}\n";
  for (size_t i = 0; i < logs.size(); ++i) {
    const auto v = renderVideo(logs[i], o.out / ("kick_" + std::to_string(i + 1) + ".mp4"),
                               config.video, 0, 1e12);
    std::printf("video: %s, %d frames\n", v.file.string().c_str(), v.frames);
  }
  std::printf("wrote %s\n", (o.out / "penalty.json").string().c_str());
  return g_interrupted ? 130 : 0;
}

int replay(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "physics", "events"},
                    {"video", "from", "to", "threads"});
  if (opt.help(kReplayHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one match log");
  const std::filesystem::path file = opt.positional()[0];
  const double from = opt.number("from", 0.0), to = opt.number("to", 1e12);
  if (to < from) throw UsageError("--to must not be before --from");
  const int threads = opt.wholeNumber("threads", 0, 1, world::PhysicsConfig::kMaxThreads);
  if (opt.has("threads") && !opt.flag("physics"))
    throw UsageError("--threads goes with --physics (the solver threads of the re-run)");
  world::MatchLogReader reader(file);
  const auto& h = reader.header().values;
  int frames = 0;
  double first_time = -1, last_time = 0;
  std::vector<world::LogFrame> all;
  world::LogFrame f;
  int events = 0;
  while (reader.next(f)) {
    if (first_time < 0) first_time = f.time;
    last_time = f.time;
    events += static_cast<int>(f.events.size());
    if (opt.flag("events"))
      for (const auto& e : f.events)
        std::printf("  %8.2f s  %-12s team %2d player %2d  %s\n", e.time, e.type.c_str(), e.team,
                    e.player, e.detail.c_str());
    ++frames;
  }
  std::printf("%s: %d frames (%.2f .. %.2f s), %zu robots, %d referee events, seed %s, config %s\n",
              file.string().c_str(), frames, first_time, last_time, reader.header().robots.size(),
              events, h.count("seed") ? h.at("seed").c_str() : "?",
              h.count("config") ? h.at("config").c_str() : "?");
  int status = 0;
  if (opt.flag("physics")) {
    if (!h.count("config")) throw std::runtime_error(file.string() + ": no config in the header");
    MatchConfig config = loadMatchConfig(h.at("config"));
    if (h.count("config_hash") && h.at("config_hash") != config.hash)
      std::printf("warning: %s changed since the log was written\n", config.file.c_str());
    if (h.count("half_duration")) config.half_duration = std::stod(h.at("half_duration"));
    const uint64_t seed = std::stoull(h.at("seed"));
    MatchSession session(config, seed, threads);
    // The recorded commands are what each period applied: replayed serially
    // through the same pipeline (and gate) as the game, whatever its mode.
    sim::Simulation simulation(session.world());
    session.attach(simulation);
    sim::LogSource recorded(file);
    simulation.addSource(recorded);
    int checked = 0;
    while (recorded.next()) {
      simulation.period();
      if (session.world().stateHash() != recorded.frame().state_hash) {
        std::printf("state hash differs at %.2f s (frame %d)\n", recorded.frame().time,
                    checked + 1);
        status = 1;
        break;
      }
      ++checked;
    }
    if (recorded.refused() > 0)
      std::printf("warning: %llu recorded commands refused (not finite or out of range)\n",
                  static_cast<unsigned long long>(recorded.refused()));
    if (status == 0)
      std::printf("physics replay: %d of %d periods, every state hash equal\n", checked, frames);
  }
  if (opt.has("video")) {
    VideoSettings v;
    if (h.count("config")) {
      try {
        v = loadMatchConfig(h.at("config")).video;
      } catch (const std::exception&) {
      }
    }
    const auto r = renderVideo(file, opt.get("video", ""), v, from, to);
    std::printf("video: %s, %d frames\n", r.file.string().c_str(), r.frames);
  }
  return status;
}

}  // namespace simsoccer::apps

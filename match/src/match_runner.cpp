#include "simsoccer/match/match_runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>

#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/match/outputs.hpp"
#include "simsoccer/net/credentials.hpp"
#include "simsoccer/net/robot_keys.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/protocol/wire.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::match {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct AgentSlot {
  int team = 0, number = 0;
  std::unique_ptr<ChildProcess> process;
  int restarts = 0;
};

// Stage record: each period into the match log (poses, joints, ball, the
// commands applied, the game packet, the referee's events, the state hash).
class LogRecorder : public sim::Recorder {
 public:
  LogRecorder(world::MatchLogWriter& log, RunResult& result) : log_(log), result_(result) {}
  // Robots' LED colours (LoLA robots), if any.
  std::function<std::optional<std::array<uint8_t, 9>>(world::RobotId)> leds;
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
    if (leds)
      for (world::RobotId r = 0; r < w.robotCount(); ++r) frame.robots[r].leds = leds(r);
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

}  // namespace

std::vector<std::string> agentCommand(const MatchSession& session, const RunOptions& o, int team,
                                      int number) {
  const MatchConfig& c = session.config();
  SoccerAgentOptions ao;
  ao.team = team;
  ao.player = number;
  ao.domain = static_cast<int>(o.domain);
  ao.dds_config = o.secure.empty() ? o.dds_config
                                   : net::credentialConfig(o.secure, net::teamIdentity(team));
  ao.role = c.role;
  ao.field = session.world().scenario().field_file;
  for (world::RobotId r = 0; r < session.world().robotCount(); ++r) {
    const auto& info = session.world().robot(r);
    if (info.team == team && info.number == number) ao.robot = info.model->source_file;
  }
  ao.config = c.agent_config;
  ao.motions = c.agent_motions;
  ao.team_number = c.team_numbers[static_cast<size_t>(team)];
  ao.seed = o.seed * 1000 + static_cast<uint64_t>(team * 100 + number);
  ao.get_up = c.get_up;
  // A lockstep period may wait for a LoLA robot's client to connect again (up to
  // reconnect_timeout, then the lockstep timeout for its answer) with no frame going out.
  if (!session.lolaRobots().empty() && !o.realtime)
    ao.gone_after = 5.0 + c.lola.reconnect_timeout + c.command_timeout;
  return soccerAgentCommand(ao);
}

RunResult play(MatchSession& session, const RunOptions& o, world::MatchLogWriter& log) {
  RunResult result;
  world::World& w = session.world();
  const MatchConfig& c = session.config();
  sim::SimulationConfig simc;
  simc.mode = o.mode.value_or(sim::defaultMode(!o.realtime));
  simc.lockstep = !o.realtime;
  sim::Simulation simulation(w, simc);
  session.attach(simulation);
  LogRecorder recorder(log, result);
  simulation.addRecorder(recorder);
  net::ServerConfig sc;
  sc.dds.domain = o.domain;
  sc.dds.config_file = o.secure.empty() ? o.dds_config : net::credentialConfig(o.secure, "simulator");
  sc.lockstep = !o.realtime;
  sc.command_timeout = c.command_timeout;
  sc.team_message_delay = c.message_delay;
  sc.team_message_loss = c.message_loss;
  sc.not_served = session.lolaRobots();
  sc.notice = o.notice;
  // The agents this match starts get their robots' keys: nobody else can
  // claim their robots, also while one restarts (net/robot_keys.hpp).
  if (!o.external) sc.reserve = net::newMatchSecret();
  // LoLA robots: one socket each under the run's folder, a command source
  // beside DDS, their cameras and field network; their clients are started
  // here if the config names one.
  const std::unique_ptr<LolaRobots> lola_robots = openLolaRobots(session, simulation, o.out,
                                                                 !o.realtime, o.notice);
  if (lola_robots) recorder.leds = [&](world::RobotId r) { return lola_robots->leds(r); };
  std::vector<std::unique_ptr<ChildProcess>> lola_clients;
  for (size_t i = 0; lola_robots && i < c.lola.robots.size() && !c.lola.client.empty(); ++i) {
    std::vector<std::string> args;
    const std::string socket = lolaSocketPath(o.out, c.lola.robots[i]).string();
    for (std::string a : c.lola.client) {
      for (size_t at = a.find("{socket}"); at != std::string::npos;
           at = a.find("{socket}", at + socket.size()))
        a.replace(at, 8, socket);
      args.push_back(a);
    }
    lola_clients.push_back(std::make_unique<ChildProcess>(args));
    if (!lola_clients.back()->started())
      throw std::runtime_error("lola.client: cannot start " + args[0] + " (" +
                               std::strerror(lola_clients.back()->spawnError()) + ")");
  }
  const auto stopRequested = [&] { return o.stop_requested && o.stop_requested(); };
  // The LoLA clients (started by hand, maybe much later) first: agents started before would
  // see no frame while this waits, take the simulator for gone and exit.
  if (lola_robots) {
    const auto t_lola = Clock::now();
    while (!stopRequested() && !lola_robots->endpoint().waitForClients(0.5))
      if (secondsSince(t_lola) > c.lola.connect_timeout) {
        if (o.notice)
          o.notice("not every LoLA client connected within " +
                   fixedNumber(c.lola.connect_timeout, 0) +
                   " s: the match starts, their robots hold");
        break;
      }
  }
  net::SimServer server(simulation, sc);
  // The agents find the game state when they start.
  server.publishGameState(session.controlData(), session.game().leftTeam());
  auto startAgent = [&](int team, int number) {  // the same for a restart
    // The agent exits when this process does, even killed (simsoccer-agent
    // asks the kernel for SIGTERM when its parent dies).
    std::vector<std::string> environment{std::string(protocol::kParentPidVariable) + "=" +
                                         std::to_string(::getpid())};
    if (sc.reserve)
      environment.push_back(std::string(net::kRobotKeyVariable) + "=" +
                            net::toHex(net::robotKey(*sc.reserve, team, number)));
    return std::make_unique<ChildProcess>(match::agentCommand(session, o, team, number),
                                          std::move(environment));
  };
  std::vector<AgentSlot> agents;
  const auto isLola = [&](world::RobotId r) {
    return std::find(session.lolaRobots().begin(), session.lolaRobots().end(), r) !=
           session.lolaRobots().end();
  };
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    if (isLola(r)) continue;
    AgentSlot a;
    a.team = w.robot(r).team;
    a.number = w.robot(r).number;
    if (!o.external) {
      a.process = startAgent(a.team, a.number);
      if (!a.process->started())
        throw std::runtime_error("cannot start " + agentProgram().string());
    }
    agents.push_back(std::move(a));
  }
  const auto claimed = [&](const AgentSlot& a) {
    for (world::RobotId r = 0; r < w.robotCount(); ++r)
      if (w.robot(r).team == a.team && w.robot(r).number == a.number) return server.stats(r).owned;
    return false;
  };
  const auto t_wait = Clock::now();
  const size_t dds_robots = w.robotCount() - session.lolaRobots().size();
  while (!stopRequested() && !server.waitForOwners(dds_robots, 0.5)) {
    // An agent that exits before it claims its robot exits on its start-up (its message is
    // above): restarting it would fail the same way. (One that claimed and then exited is
    // restarted once the game runs, as before.)
    for (AgentSlot& a : agents)
      if (a.process && !a.process->running() && !claimed(a))
        throw std::runtime_error("the agent of team " + std::to_string(a.team) + " player " +
                                 std::to_string(a.number) + " exited (status " +
                                 std::to_string(a.process->exitStatus()) +
                                 ") before it claimed its robot");
    if (secondsSince(t_wait) > 60.0)
      throw std::runtime_error("agents did not claim their robots within 60 s");
  }
  const auto t0 = Clock::now();
  double last_progress = -1.0;
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
                    fixedNumber(w.time(), 2).c_str(), a.team, a.number, a.process->exitStatus(),
                    a.restarts);
      result.agent_events.push_back(buf);
      a.process = startAgent(a.team, a.number);
    }
  };
  sim::RunLoop loop(simulation, o.realtime ? sim::Pacing::RealTime : sim::Pacing::Lockstep);
  loop.run(
      [&] {
        return session.over() || stopRequested() || result.aborted ||
               (o.max_seconds > 0 && w.time() >= o.max_seconds - 1e-9);
      },
      -1,
      [&] {
        ++i;
        if (lola_robots) lola_robots->afterPeriod();
        // Every period: a crashed agent's robot is released at once, so
        // lockstep waits for it in one period at most.
        if (!o.external) superviseAgents();
        if (o.progress && secondsSince(t0) - last_progress > 0.25) {
          last_progress = secondsSince(t0);
          o.progress(session, last_progress);
        }
      });
  result.interrupted = stopRequested();
  result.wall = secondsSince(t0);
  result.longest_wait = simulation.profile().longest_collect_s;
  result.final_hash = w.stateHash();
  for (world::RobotId r = 0; r < w.robotCount(); ++r)
    result.missed_commands.push_back(server.stats(r).missed);
  if (lola_robots) result.lola = lola_robots->results();
  for (AgentSlot& a : agents)
    if (a.process) a.process->stop();
  for (auto& client : lola_clients) client->stop();
  log.flush();
  return result;
}

world::MatchLogHeader logHeader(const MatchSession& s, const RunOptions& o) {
  world::MatchLogHeader h;
  const world::World& w = s.world();
  h.values["config"] = std::filesystem::absolute(s.config().file).string();
  h.values["config_hash"] = s.config().hash;
  h.values["scenario"] = std::filesystem::absolute(s.config().scenario).string();
  h.values["seed"] = std::to_string(o.seed);
  h.values["control_period"] = fixedNumber(w.scenario().physics.control_period, 6);
  if (s.config().half_duration) h.values["half_duration"] = fixedNumber(*s.config().half_duration, 3);
  for (world::RobotId r = 0; r < w.robotCount(); ++r)
    h.robots.push_back({w.robot(r).team, w.robot(r).number,
                        static_cast<int>(w.robot(r).model->body->joints.size())});
  return h;
}

void prepareOut(const std::filesystem::path& out, bool overwrite) {
  std::error_code ec;
  for (const char* earlier : {"summary.json", "match.log", "penalty.json", "game_1"})
    if (!overwrite && std::filesystem::exists(out / earlier, ec))
      throw std::runtime_error(out.string() + " holds an earlier run (" + earlier +
                               "): give another --out, or --overwrite to replace it");
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

RunResult playMatch(MatchSession& session, const RunOptions& o) {
  prepareOut(o.out, o.overwrite);
  const auto log_file = o.out / "match.log";
  RunResult r;
  {
    std::optional<world::MatchLogWriter> log(std::in_place, log_file, logHeader(session, o));
    try {
      r = play(session, o, *log);
    } catch (...) {
      // Failed before the first period (agents, DDS, LoLA): no game to keep, and a header
      // alone would make the folder look like an earlier run to the next one.
      const bool empty = log->frames() == 0;
      log.reset();
      std::error_code ec;
      if (empty) std::filesystem::remove(log_file, ec);
      throw;
    }
    r.log_bytes = log->bytes();
  }
  writeSummary(o.out / "summary.json", session, r, o);
  if (!r.interrupted) {
    writeHeatmap(log_file, o.out / "heatmap.png");
    if (o.video)
      r.video_frames =
          renderVideo(log_file, o.out / "match.mp4", session.config().video, 0, 1e12).frames;
  }
  return r;
}

PenaltyResult playPenalties(
    const MatchConfig& config, const RunOptions& o, int kicks, int video_kicks,
    const std::function<void(int kick, uint64_t seed, const std::string& outcome)>& on_kick) {
  prepareOut(o.out, o.overwrite);
  PenaltyResult result;
  std::vector<std::filesystem::path> logs;
  for (int k = 0; k < kicks && !(o.stop_requested && o.stop_requested()); ++k) {
    RunOptions ko = o;
    ko.seed = o.seed + static_cast<uint64_t>(k);
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
    result.goals += outcome == "goal";
    result.saved += outcome == "saved";
    result.missed += outcome == "missed";
    result.timeout += outcome == "timeout";
    result.outcomes.push_back(outcome);
    if (on_kick) on_kick(k + 1, ko.seed, outcome);
    if (k < video_kicks)
      logs.push_back(log_file);
    else
      std::filesystem::remove(log_file);
  }
  result.interrupted = o.stop_requested && o.stop_requested();
  const int n = static_cast<int>(result.outcomes.size());
  const Proportion p = wilsonInterval(result.goals, n);
  std::ofstream out(o.out / "penalty.json");
  out << "{\n  \"config\": " << jsonString(config.file) << ",\n  \"seed\": " << o.seed
      << ",\n  \"kicks\": " << n << ",\n  \"scoring_rate\": " << fixedNumber(p.rate, 3)
      << ",\n  \"ci95\": [" << fixedNumber(p.low, 3) << ", " << fixedNumber(p.high, 3)
      << "],\n  \"counts\": {\"goal\": " << result.goals << ", \"saved\": " << result.saved
      << ", \"missed\": " << result.missed << ", \"timeout\": " << result.timeout
      << "},\n  \"outcomes\": [";
  for (size_t i = 0; i < result.outcomes.size(); ++i)
    out << (i ? ", " : "") << jsonString(result.outcomes[i]);
  out << "]\n}\n";
  if (!out) throw std::runtime_error((o.out / "penalty.json").string() + ": cannot write");
  for (size_t i = 0; i < logs.size(); ++i)
    result.videos.push_back(renderVideo(logs[i], o.out / ("kick_" + std::to_string(i + 1) + ".mp4"),
                                        config.video, 0, 1e12)
                                .file);
  return result;
}

}  // namespace simsoccer::match

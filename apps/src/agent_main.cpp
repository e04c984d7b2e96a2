// simsoccer-agent: the built-in agent. It claims a robot, then answers every
// SensorFrame: with --role, the soccer behaviour and the motion layer (walk,
// kick, fall detector) driven by the robot's perception, the GameState and
// team messages; without, simple modes (stand and nod, walk at a velocity)
// and test modes that send malformed commands or stop answering.
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>

#include "agent_help.hpp"
#include "agent_modes.hpp"
#include "agent_soccer.hpp"
#include "cli.hpp"
#include "simsoccer/agents/agent_client.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/robots/robot_model.hpp"

int main(int argc, char** argv) {
  using namespace simsoccer;
  try {
    const apps::Options opt(
        argc, argv, 1, {"help", "get-up", "no-get-up", "verbose"},
        {"team",     "player",    "domain",      "dds-config", "lease",
         "robot",    "mode",      "stall-after", "ticks",      "claim-timeout",
         "vx",       "vy",        "turn",        "role",       "config",
         "motions",  "field",     "team-number", "seed",       "game-state-wait",
         "if-owned", "gone-after"});
    if (opt.help(simsoccer::apps::kAgentHelp)) return 0;
    opt.noPositional();
    if (!opt.has("team") || !opt.has("player"))
      throw apps::UsageError("--team and --player are required");
    const int team = opt.wholeNumber("team", 0, 0, 1);
    const int player = opt.wholeNumber("player", 1, 1, 20);
    net::DomainConfig dds;
    dds.domain = opt.domain("domain", 0);
    dds.config_file = apps::findConfig(opt.get("dds-config", ""), "configs/dds/loopback.xml");
    dds.lease = opt.number("lease", dds.lease);
    if (!(dds.lease >= net::DomainConfig::kMinLease && dds.lease <= net::DomainConfig::kMaxLease))
      throw apps::UsageError("--lease must be between " +
                             engine::formatNumber(net::DomainConfig::kMinLease) + " and " +
                             engine::formatNumber(net::DomainConfig::kMaxLease) + " s");
    const auto robot_file = apps::findConfig(opt.get("robot", ""), "robots/nao_v6_h25.yaml");
    const std::string mode = opt.get("mode", "nod");
    const std::string if_owned = opt.get("if-owned", "wait");
    if (if_owned != "wait" && if_owned != "refuse")
      throw apps::UsageError("--if-owned must be wait or refuse, not '" + if_owned + "'");
    if (mode != "nod" && mode != "walk" && mode != "garbage" && mode != "stall")
      throw apps::UsageError("--mode must be nod, walk, garbage or stall");
    const long stall_after = opt.wholeNumber("stall-after", 50, 0, 1000000000);
    const long max_ticks = opt.wholeNumber("ticks", -1, -1, 2000000000);
    if (max_ticks == 0) throw apps::UsageError("--ticks must be >= 1 (or -1: no limit)");
    if (opt.has("stall-after") && mode != "stall")
      throw apps::UsageError("--stall-after goes with --mode stall");
    if (opt.has("mode") && opt.has("role"))
      throw apps::UsageError("--mode and --role exclude each other (--role plays soccer)");

    const robots::RobotModel model = robots::loadRobotModel(robot_file);
    // The motions and gaits: a folder per robot model that has its own (motionsFolder).
    const std::filesystem::path motions =
        apps::findConfig(opt.get("motions", ""), "configs/motions");
    if (!std::filesystem::is_directory(motions))
      throw apps::UsageError("--motions: no such folder: " + motions.string());
    const std::filesystem::path robot_motions = agents::motionsFolder(motions, model);

    // Soccer (--role): behaviour and motion, loaded before claiming so a bad file stops here.
    apps::SoccerPlayer::refuseWithoutRole(opt);
    std::optional<apps::SoccerPlayer> soccer;
    if (opt.has("role")) soccer.emplace(opt, model, robot_motions, team, player);
    const bool verbose = opt.flag("verbose");
    apps::SimpleModes simple(model, robot_motions, mode, opt.number("vx", 0.2),
                             opt.number("vy", 0.0), opt.number("turn", 0.0));

    // Started by a match (which names itself): go when it goes, also when it
    // was killed with SIGKILL and could not stop its agents.
    if (const char* parent = std::getenv(simsoccer::protocol::kParentPidVariable);
        parent && *parent) {
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (::getppid() != static_cast<pid_t>(std::atol(parent))) return 4;  // already gone
    }
    // A match that reserves its robots hands each agent its robot's key in
    // the environment (not on the command line, which every user can read).
    std::optional<net::RobotKey> key;
    if (const char* hex = std::getenv(net::kRobotKeyVariable); hex && *hex) {
      std::string why;
      key = net::keyFromHex(hex, &why);
      if (!key) throw apps::UsageError(std::string(net::kRobotKeyVariable) + ": " + why);
      ::unsetenv(net::kRobotKeyVariable);  // not inherited by anything this starts
    }
    agents::AgentClient client(dds, team, player, key);
    // The referee's state before claiming: the simulator starts once every
    // robot is claimed, so the first frame is answered with it however late
    // it would have arrived (otherwise the first periods may be played
    // without it, and the same seed gives another game).
    const double game_wait = opt.nonNegative("game-state-wait", 0.0);
    const double gone_after = opt.positive("gone-after", 5.0);
    if (soccer && game_wait > 0.0 && !client.waitForGameState(game_wait))
      std::fprintf(stderr,
                   "simsoccer-agent: robot (%d, %d): no GameState within %g s; playing without "
                   "it until one comes (a lockstep run may then differ between runs)\n",
                   team, player, game_wait);
    if (!client.claim(opt.positive("claim-timeout", 10.0),
                      if_owned == "refuse" ? agents::AgentClient::IfOwned::Refuse
                                           : agents::AgentClient::IfOwned::WaitForRelease)) {
      std::fprintf(stderr,
                   "simsoccer-agent: robot (%d, %d) not granted on DDS domain %u (no simulator "
                   "there, or another participant owns it)\n",
                   team, player, dds.domain);
      return 3;
    }
    // Answers run in the DDS receive thread (AgentClient::onFrame): no
    // thread hop between a frame arriving and its command leaving.
    std::atomic<long> answered{0};
    std::atomic<int64_t> last_frame_ns{0};
    auto now_ns = [] {
      return std::chrono::duration_cast<std::chrono::nanoseconds>(
                 std::chrono::steady_clock::now().time_since_epoch())
          .count();
    };
    last_frame_ns = now_ns();
    client.onFrame([&](const simsoccer_msg_SensorFrame& frame) {
      last_frame_ns = now_ns();
      if (mode == "stall" && answered >= stall_after) return;
      if (max_ticks >= 0 && answered >= max_ticks) return;
      if (soccer)
        soccer->answer(frame, client, verbose);
      else
        simple.answer(frame, client, team, player);
      ++answered;
    });
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (max_ticks >= 0 && answered >= max_ticks) {
        client.onFrame(nullptr);
        return 0;
      }
      if (static_cast<double>(now_ns() - last_frame_ns) > gone_after * 1e9) {
        client.onFrame(nullptr);
        std::fprintf(stderr, "simsoccer-agent: no frame for %g s, the simulator is gone\n",
                     gone_after);
        return 4;
      }
    }
  } catch (const apps::UsageError& e) {
    std::fprintf(stderr, "simsoccer-agent: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simsoccer-agent: error: %s\n", e.what());
    return 1;
  }
}

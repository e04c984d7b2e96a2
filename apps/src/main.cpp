// simsoccer: the command-line entry point. Subcommands dispatch to their own
// files; every one answers --help.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "cli.hpp"
#include "simsoccer/engine/config.hpp"

namespace {

const char* kUsage =
    "usage: simsoccer <command> [options]\n"
    "\n"
    "commands:\n"
    "  match CONFIG    play a whole game with agent processes: summary, log, video, heatmap\n"
    "  penalty CONFIG  N seeded penalty kicks, striker against goalkeeper: scoring rate\n"
    "  replay LOG      re-render (--video) or re-simulate (--physics) a match log\n"
    "  check SCENARIO  load and validate a scenario file, print what it contains\n"
    "  bench physics   physics scaling benchmark (steps/s against robot count)\n"
    "  bench sensors   sonar tracer (batched vs Bullet rayTest) and sensor cost per robot count\n"
    "  bench net       lockstep with real agent processes over DDS: overhead and bytes per tick\n"
    "  bench cameras   every robot's two cameras rendered through EGL: views/s, ms per frame, RTF\n"
    "  bench motion    the agents' motion and behaviour: walk, kick, get-up, striker, penalty\n"
    "  bench scaling   the full pipeline with agent processes, 1..22 robots, vs USARSim\n"
    "  serve SCENARIO  run a scenario as a DDS simulator for agents started elsewhere\n"
    "  lola-run        start a team's robot binary with a simulated Nao's LoLA socket\n"
    "  booster-run     start a team's Booster SDK program attached to one simulated K1\n"
    "  soak [CONFIG]   matches back to back with agents killed: memory, descriptors, threads\n"
    "  credentials DIR DDS Security certificates and permissions for a secure match\n"
    "\n"
    "Run 'simsoccer <command> --help' for the options of a command.\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace simsoccer::apps;
  const std::string cmd = argc > 1 ? argv[1] : "";
  if (cmd.empty() || cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::fputs(kUsage, cmd.empty() ? stderr : stdout);
    return cmd.empty() ? 2 : 0;
  }
  try {
    if (cmd == "check") return check(argc, argv, 2);
    if (cmd == "serve") return serve(argc, argv, 2);
    if (cmd == "match") return match(argc, argv, 2);
    if (cmd == "penalty") return penalty(argc, argv, 2);
    if (cmd == "replay") return replay(argc, argv, 2);
    if (cmd == "lola-run") return lolaRun(argc, argv, 2);
    if (cmd == "booster-run") return boosterRun(argc, argv, 2);
    if (cmd == "soak") return soak(argc, argv, 2);
    if (cmd == "credentials") return credentials(argc, argv, 2);
    if (cmd == "bench") {
      const std::string sub = argc > 2 ? argv[2] : "";
      if (sub == "physics") return benchPhysics(argc, argv, 3);
      if (sub == "sensors") return benchSensors(argc, argv, 3);
      if (sub == "net") return benchNet(argc, argv, 3);
      if (sub == "cameras") return benchCameras(argc, argv, 3);
      if (sub == "motion") return benchMotion(argc, argv, 3);
      if (sub == "scaling") return benchScaling(argc, argv, 3);
      if (sub.empty() || sub == "--help" || sub == "-h") {
        std::printf(
            "usage: simsoccer bench physics|sensors|net|cameras|motion|scaling [OPTIONS]\n"
            "(simsoccer bench NAME --help explains each one)\n");
        return sub.empty() ? 2 : 0;
      }
      std::fprintf(stderr,
                   "simsoccer bench: unknown benchmark '%s' (available: physics, sensors, net, "
                   "cameras, motion, scaling)\n",
                   sub.c_str());
      return 2;
    }
    std::fprintf(stderr, "simsoccer: unknown command '%s'\n\n%s", cmd.c_str(), kUsage);
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "simsoccer %s: %s\n", cmd.c_str(), e.what());
    return 2;
  } catch (const simsoccer::engine::ConfigError& e) {
    std::fprintf(stderr, "simsoccer: config error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simsoccer: error: %s\n", e.what());
    return 1;
  }
}

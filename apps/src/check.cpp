// simsoccer check: loads a config file of any kind the programs read (a scenario with its field
// and robot models and the world built from them; a match or penalty config with everything it
// names; a field, robot, rule book, behaviour or gait file alone) and prints what it holds, or
// the first config error.
#include <cstdio>
#include <string>

#include "bench_motion/trial.hpp"
#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/agents/motion/gait.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/robots/robot_model.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {

namespace {
const char* kCheckHelp =
    "usage: simsoccer check FILE.yaml\n"
    "\n"
    "Loads a config file and prints a summary, or stops at the first error with\n"
    "FILE: KEY.PATH: reason and exit status 1. What is loaded depends on the file's kind (its\n"
    "first key):\n"
    "  scenario        its field and robot model files, and the world built from them\n"
    "                  (nothing is stepped): the robots and the initial state hash\n"
    "  match, penalty  the match config with its scenario (as above), rule book, agent\n"
    "                  behaviour file and every robot's motions and gait\n"
    "  bench           a benchmark scene (configs/bench/physics*.yaml), its scenario as above\n"
    "  targets         bench motion's robot file (configs/bench/motion_*.yaml)\n"
    "  field, robot, rules, behaviour, walk/kick (a gait)  that file alone\n";

void printScenario(const std::filesystem::path& file) {
  const world::World w = world::World::fromFile(file);
  const auto& s = w.scenario();
  std::printf("%s: scenario '%s' is valid\n", s.source_file.c_str(), s.name.c_str());
  std::printf("  field %s (%.1f x %.1f m), dt %.1f ms, control period %.1f ms, seed %llu\n",
              w.field().name.c_str(), w.field().length, w.field().width, s.physics.dt * 1e3,
              s.physics.control_period * 1e3, static_cast<unsigned long long>(s.seed));
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const auto& info = w.robot(r);
    const engine::Vec3 p = w.torsoPose(r).translation();
    std::printf("  robot %u: team %d number %d, %s (%.3f kg), torso at (%.2f, %.2f, %.3f)\n",
                r.value(), info.team, info.number, info.model->name.c_str(),
                info.model->body->totalMass(), p.x(), p.y(), p.z());
  }
  std::printf("  state hash %016llx\n", static_cast<unsigned long long>(w.stateHash()));
}

}  // namespace

int check(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"}, {});
  if (opt.help(kCheckHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one config file");
  const std::filesystem::path file = opt.positional()[0];
  const engine::ConfigNode root = engine::ConfigNode::loadFile(file);
  const char* f = file.c_str();
  if (root.has("match") || root.has("penalty")) {
    const match::MatchConfig c = match::loadMatchConfig(file);
    std::printf("%s: %s config '%s' is valid: rule book %s, agents %s (role %s)\n", f,
                c.penalty_kicks > 0 ? "penalty" : "match", c.name.c_str(), c.rules.c_str(),
                c.agent_config.empty() ? "(the agent's default)" : c.agent_config.c_str(),
                c.role.c_str());
    printScenario(c.scenario);
  } else if (root.has("bench")) {
    const BenchConfig b = loadBenchConfig(file);
    std::printf("%s: benchmark scene is valid (%zu robot counts)\n", f, b.robots.size());
  } else if (root.has("targets")) {
    const motion::MotionBench b = motion::loadMotionBench(file);
    std::printf("%s: motion bench of %s is valid\n", f, b.robot.c_str());
  } else if (root.has("scenario") || root.has("robot_model") || root.has("robots")) {
    printScenario(file);  // (one without `scenario:` is told it misses it)
  } else if (root.has("field")) {
    const fields::FieldModel m = fields::loadFieldModel(file);
    std::printf("%s: field '%s' is valid (%.1f x %.1f m)\n", f, m.name.c_str(), m.length, m.width);
  } else if (root.has("robot")) {
    const robots::RobotModel m = robots::loadRobotModel(file);
    std::printf("%s: robot '%s' is valid (%zu links, %zu joints, %.3f kg)\n", f, m.name.c_str(),
                m.body->links.size(), m.body->joints.size(), m.body->totalMass());
  } else if (root.has("rules")) {
    const referee::RuleBook r = referee::loadRuleBook(file);
    std::printf("%s: rule book '%s' is valid (%d players a team, %d halves of %.0f s)\n", f,
                r.name.c_str(), r.players_per_team, r.halves, r.half_duration);
  } else if (root.has("behaviour") || root.has("base")) {
    agents::loadBehaviourConfig(file);
    std::printf("%s: agent behaviour file is valid\n", f);
  } else if (root.has("walk") || root.has("kick")) {
    agents::loadGait(file);
    std::printf("%s: gait file is valid\n", f);
  } else {
    root.fail(
        "not a file `check` knows: its keys name the kind (scenario, match, penalty, bench, "
        "targets, field, robot, rules, behaviour, or walk/kick for a gait)");
  }
  return 0;
}

}  // namespace simsoccer::apps

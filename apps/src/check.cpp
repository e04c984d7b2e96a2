// simsoccer check: loads a scenario with its field and robot models, builds
// the world, and prints what it contains, or the first config error.
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {

namespace {
const char* kCheckHelp =
    "usage: simsoccer check SCENARIO.yaml\n"
    "\n"
    "Loads the scenario, its field and robot model files, builds the world (nothing is\n"
    "stepped) and prints a summary. A bad file stops with FILE: KEY.PATH: reason and exit\n"
    "status 1.\n";
}  // namespace

int check(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"}, {});
  if (opt.help(kCheckHelp)) return 0;
  if (opt.positional().size() != 1) throw UsageError("expected one scenario file");
  const world::World w = world::World::fromFile(opt.positional()[0]);
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
  return 0;
}

}  // namespace simsoccer::apps

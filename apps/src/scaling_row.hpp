// One row of `simsoccer bench scaling`: N robots with their agent processes
// over loopback DDS in lockstep under the referee, one period mode, timed per
// pipeline stage.
#pragma once

#include <cstdint>
#include <filesystem>

#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/scenario.hpp"

namespace simsoccer::apps {

// One robot count in one period mode: speed and the time per control period per stage.
struct ScalingRow {
  int robots = 0;
  sim::Mode mode = sim::Mode::Serial;
  double steps_per_s = 0, fps = 0, rtf = 0;
  double physics_ms = 0, sensors_ms = 0, perception_ms = 0, messaging_ms = 0, referee_ms = 0,
         render_ms = 0;
  uint64_t missed = 0;
  double cpu_ms = -1;  // CPU time of the simulator and all agents per period (-1: unknown)
  int period_cpu = -1;  // the CPU the periods had to themselves (-1: none; sim/cores.hpp)
  size_t guests = 0;    // agents lent that CPU's waits at the run's last balance
};

// The robot: a Nao on the SPL field (the 3D-league-sized field beyond 14 robots) with the
// default agent config, or another robot with its motion bench's field and agent config
// (configs/bench/motion_<robot>.yaml: the K1 on the HSL M-Field).
struct ScalingRobot {
  std::filesystem::path robot_model, field, agents;  // empty field: the Nao's choice
  // The physics step and the sweeps over the joint rows (0: the defaults).
  double dt = 0.0;
  int joint_sweeps = 0;
};

// N robots in two teams at their kick-off places, perception on.
world::Scenario scalingScenario(int n, bool cameras, int threads, const ScalingRobot& robot);
// Runs `seconds` simulated with N agent processes on DDS domain `domain`;
// `own_core`: a pipelined row's periods on a CPU of their own.
ScalingRow runRow(int n, double seconds, bool cameras, sim::Mode mode, int threads, uint32_t domain,
                  const ScalingRobot& robot, bool own_core = true);

}  // namespace simsoccer::apps

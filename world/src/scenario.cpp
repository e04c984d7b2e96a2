#include "simsoccer/world/scenario.hpp"

#include <cmath>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::world {

using engine::ConfigNode;

Scenario loadScenario(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"scenario", "field", "robot_model", "physics", "seed", "placement_noise", "ball",
                  "robots", "sensors", "bench"});
  Scenario s;
  s.source_file = file.string();
  s.name = root["scenario"].string();
  s.field_file = engine::resolveBeside(s.source_file, root["field"].string());
  s.robot_model_file = engine::resolveBeside(s.source_file, root["robot_model"].string());
  for (const auto& [key, path] :
       {std::pair{"field", s.field_file}, std::pair{"robot_model", s.robot_model_file}})
    if (!std::filesystem::exists(path)) root.failKey(key, "file not found: " + path.string());

  const ConfigNode ph = root["physics"];
  ph.allowOnly({"dt", "control_period", "solver_iterations", "friction_directions", "gravity"});
  s.physics.dt = ph["dt"].positive();
  s.physics.control_period = ph["control_period"].positive();
  s.physics.solver_iterations = ph.integer("solver_iterations", s.physics.solver_iterations);
  if (s.physics.solver_iterations < 1) ph.failKey("solver_iterations", "must be >= 1");
  s.physics.friction_directions = ph.integer("friction_directions", s.physics.friction_directions);
  if (s.physics.friction_directions != 1 && s.physics.friction_directions != 2)
    ph.failKey("friction_directions", "must be 1 or 2");
  s.physics.gravity = ph.number("gravity", s.physics.gravity);
  const double ratio = s.physics.control_period / s.physics.dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio || std::round(ratio) < 1.0)
    ph.failKey("control_period", "must be a whole multiple of dt (" +
                                     engine::formatNumber(s.physics.dt) + " s), got " +
                                     engine::formatNumber(s.physics.control_period) + " s");

  const int seed = root["seed"].integer();
  if (seed < 0) root.failKey("seed", "must be >= 0");
  s.seed = static_cast<uint64_t>(seed);
  if (auto n = root.optional("placement_noise")) {
    n->allowOnly({"position", "yaw", "joints"});
    s.noise.position = n->has("position") ? (*n)["position"].nonNegative() : 0.0;
    s.noise.yaw = n->has("yaw") ? (*n)["yaw"].nonNegative() : 0.0;
    s.noise.joints = n->has("joints") ? (*n)["joints"].nonNegative() : 0.0;
  }
  if (auto n = root.optional("sensors")) {
    n->allowOnly({"enabled", "sonar", "imu"});
    s.sensors.enabled = n->boolean("enabled", true);
    if (auto sonar = n->optional("sonar")) {
      sonar->allowOnly({"rays", "update_period"});
      s.sensors.sonar_rays = sonar->integer("rays", s.sensors.sonar_rays);
      if (s.sensors.sonar_rays < 1 || s.sensors.sonar_rays > 256)
        sonar->failKey("rays", "must be 1..256");
      if (sonar->has("update_period"))
        s.sensors.sonar_period = (*sonar)["update_period"].positive();
      const double k = s.sensors.sonar_period / s.physics.control_period;
      if (std::abs(k - std::round(k)) > 1e-9 * k || std::round(k) < 1.0)
        sonar->failKey("update_period", "must be a whole multiple of the control period (" +
                                            engine::formatNumber(s.physics.control_period) + " s)");
    }
    if (auto imu = n->optional("imu")) {
      imu->allowOnly({"gyro_noise", "gyro_bias", "accel_noise", "accel_bias", "angle_noise"});
      auto vec = [&](const char* key, engine::Vec3& out, bool non_negative) {
        if (!imu->has(key)) return;
        out = (*imu)[key].vec3();
        if (non_negative && out.minCoeff() < 0.0)
          imu->failKey(key, "standard deviations must be >= 0");
      };
      vec("gyro_noise", s.sensors.gyro_noise, true);
      vec("gyro_bias", s.sensors.gyro_bias, false);
      vec("accel_noise", s.sensors.accel_noise, true);
      vec("accel_bias", s.sensors.accel_bias, false);
      vec("angle_noise", s.sensors.angle_noise, true);
    }
  }
  if (auto b = root.optional("ball")) {
    b->allowOnly({"position", "velocity"});
    const auto p = (*b)["position"].numbers();
    if (p.size() != 2 && p.size() != 3) b->failKey("position", "expected [x, y] or [x, y, z]");
    s.ball_position = engine::Vec3(p[0], p[1], p.size() == 3 ? p[2] : -1.0);
    if (auto v = b->optional("velocity")) s.ball_velocity = v->vec3();
  }
  if (auto robots = root.optional("robots")) {
    for (const ConfigNode& n : robots->items()) {
      n.allowOnly({"team", "number", "pose", "posture", "model"});
      RobotPlacement p;
      p.team = n["team"].integer();
      if (p.team != 0 && p.team != 1) n.failKey("team", "must be 0 or 1");
      p.number = n["number"].integer();
      if (p.number < 1) n.failKey("number", "player numbers start at 1");
      const auto pose = n["pose"].numbers(3);
      p.x = pose[0];
      p.y = pose[1];
      p.yaw = pose[2];
      if (n.has("posture")) p.posture = n["posture"].string();
      if (n.has("model")) {
        p.model_file = engine::resolveBeside(s.source_file, n["model"].string()).string();
        if (!std::filesystem::exists(p.model_file))
          n.failKey("model", "file not found: " + p.model_file);
      }
      s.robots.push_back(p);
    }
  }
  return s;
}

}  // namespace simsoccer::world

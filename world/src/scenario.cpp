#include "simsoccer/world/scenario.hpp"

#include <sched.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <thread>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::world {

using engine::ConfigNode;

namespace {

// The GameController's packets carry 20 players a team (protocol::kMaxPlayers).
const std::string kPlayerNumbers = "player numbers are 1.." + std::to_string(protocol::kMaxPlayers);

void readRate(const ConfigNode& n, double control_period, double& rate) {
  if (!n.has("rate")) return;
  rate = n["rate"].positive();
  if (rate * control_period > 1.0 + 1e-9)
    n.failKey("rate", "at most one image per control period (" +
                          engine::formatNumber(1.0 / control_period) + " Hz)");
}

void readSize(const ConfigNode& n, int& width, int& height) {
  width = n.integer("width", width);
  height = n.integer("height", height);
  if (width < 2 || width > 4096 || width % 2 != 0)
    n.failKey("width", "must be even and 2..4096 px (YUYV pairs pixels)");
  if (height < 1 || height > 4096) n.failKey("height", "must be 1..4096 px");
}

void readCameras(const ConfigNode& n, double control_period, CameraSettings& c) {
  n.allowOnly({"enabled", "top", "bottom", "encoding", "jpeg_quality", "queue", "effects",
               "calibration", "spectator"});
  c.enabled = n.boolean("enabled", true);
  for (auto [key, spec] : {std::pair{"top", &c.top}, std::pair{"bottom", &c.bottom}}) {
    if (auto k = n.optional(key)) {
      k->allowOnly({"enabled", "width", "height", "rate"});
      spec->enabled = k->boolean("enabled", true);
      readSize(*k, spec->width, spec->height);
      readRate(*k, control_period, spec->rate);
    }
  }
  if (n.has("encoding")) {
    c.encoding = n["encoding"].string();
    if (c.encoding != "yuyv" && c.encoding != "jpeg") n.failKey("encoding", "must be yuyv or jpeg");
  }
  c.jpeg_quality = n.integer("jpeg_quality", c.jpeg_quality);
  if (c.jpeg_quality < 1 || c.jpeg_quality > 100) n.failKey("jpeg_quality", "must be 1..100");
  c.queue = n.integer("queue", c.queue);
  if (c.queue < 1 || c.queue > 64) n.failKey("queue", "must be 1..64");
  if (auto e = n.optional("effects")) {
    e->allowOnly({"noise", "motion_blur_exposure", "rolling_shutter_readout"});
    if (e->has("noise")) c.effects.noise = (*e)["noise"].nonNegative();
    if (e->has("motion_blur_exposure"))
      c.effects.motion_blur_exposure = (*e)["motion_blur_exposure"].nonNegative();
    if (e->has("rolling_shutter_readout"))
      c.effects.rolling_shutter_readout = (*e)["rolling_shutter_readout"].nonNegative();
  }
  if (auto cal = n.optional("calibration")) {
    for (const ConfigNode& k : cal->items()) {
      k.allowOnly({"team", "number", "camera", "rpy"});
      CameraCalibration x;
      x.team = k["team"].integer();
      if (x.team != 0 && x.team != 1) k.failKey("team", "must be 0 or 1");
      x.number = k["number"].integer();
      if (x.number < 1 || x.number > static_cast<int>(protocol::kMaxPlayers))
        k.failKey("number", kPlayerNumbers);
      x.camera = k["camera"].string();
      if (x.camera != "top" && x.camera != "bottom") k.failKey("camera", "must be top or bottom");
      x.rpy = k["rpy"].vec3();
      c.calibration.push_back(x);
    }
  }
  if (auto sp = n.optional("spectator")) {
    sp->allowOnly({"enabled", "position", "look_at", "width", "height", "horizontal_fov", "rate"});
    c.spectator.enabled = sp->boolean("enabled", true);
    if (sp->has("position")) c.spectator.position = (*sp)["position"].vec3();
    if (sp->has("look_at")) c.spectator.look_at = (*sp)["look_at"].vec3();
    if ((c.spectator.look_at - c.spectator.position).norm() < 1e-6)
      sp->failKey("look_at", "must differ from position");
    readSize(*sp, c.spectator.width, c.spectator.height);
    if (sp->has("horizontal_fov")) {
      c.spectator.horizontal_fov = (*sp)["horizontal_fov"].positive();
      if (c.spectator.horizontal_fov >= 3.0) sp->failKey("horizontal_fov", "must be < 3 rad");
    }
    readRate(*sp, control_period, c.spectator.rate);
  }
}

}  // namespace

Scenario loadScenario(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"scenario", "field", "robot_model", "physics", "seed", "placement_noise", "ball",
                  "robots", "sensors", "cameras", "perception", "bench"});
  Scenario s;
  s.source_file = file.string();
  s.name = root["scenario"].string();
  s.field_file = engine::resolveBeside(s.source_file, root["field"].string());
  s.robot_model_file = engine::resolveBeside(s.source_file, root["robot_model"].string());
  for (const auto& [key, path] :
       {std::pair{"field", s.field_file}, std::pair{"robot_model", s.robot_model_file}})
    if (!std::filesystem::exists(path)) root.failKey(key, "file not found: " + path.string());

  const ConfigNode ph = root["physics"];
  ph.allowOnly({"dt", "control_period", "solver_iterations", "joint_sweeps", "contact_warm_start",
                "friction_directions", "bullet_solver", "envelope_in_solver", "cull_ground_pairs",
                "gravity", "threads"});
  s.physics.dt = ph["dt"].positive();
  s.physics.control_period = ph["control_period"].positive();
  s.physics.solver_iterations = ph.integer("solver_iterations", s.physics.solver_iterations);
  if (s.physics.solver_iterations < 1) ph.failKey("solver_iterations", "must be >= 1");
  s.physics.joint_sweeps = ph.integer("joint_sweeps", s.physics.joint_sweeps);
  if (s.physics.joint_sweeps < 1 || s.physics.joint_sweeps > 16)
    ph.failKey("joint_sweeps", "must be 1..16");
  s.physics.contact_warm_start = ph.number("contact_warm_start", s.physics.contact_warm_start);
  if (!(s.physics.contact_warm_start >= 0.0 && s.physics.contact_warm_start <= 1.0))
    ph.failKey("contact_warm_start", "must be 0..1");
  s.physics.friction_directions = ph.integer("friction_directions", s.physics.friction_directions);
  if (s.physics.friction_directions != 1 && s.physics.friction_directions != 2)
    ph.failKey("friction_directions", "must be 1 or 2");
  s.physics.bullet_solver = ph.boolean("bullet_solver", s.physics.bullet_solver);
  s.physics.envelope_in_solver = ph.boolean("envelope_in_solver", s.physics.envelope_in_solver);
  s.physics.cull_ground_pairs = ph.boolean("cull_ground_pairs", s.physics.cull_ground_pairs);
  s.physics.gravity = ph.number("gravity", s.physics.gravity);
  if (const auto threads = ph.optional("threads")) {
    const std::string text = threads->raw().IsScalar() ? threads->raw().Scalar() : "";
    int n = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), n);
    if (text == "auto")
      s.physics.threads = 0;
    else if (error == std::errc() && end == text.data() + text.size() && n >= 1 &&
             n <= PhysicsConfig::kMaxThreads)
      s.physics.threads = n;
    else
      ph.failKey("threads", "must be auto or a whole number from 1 to " +
                                std::to_string(PhysicsConfig::kMaxThreads) + ", got '" + text +
                                "'");
  }
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
  if (auto c = root.optional("cameras")) readCameras(*c, s.physics.control_period, s.cameras);
  if (auto n = root.optional("perception")) {
    n->allowOnly({"enabled", "profile", "ball_range", "post_range", "robot_range", "distance_noise",
                  "bearing_noise", "miss_base", "miss_per_metre", "false_ball_rate",
                  "pose_noise_xy", "pose_noise_yaw", "pose_noise_time"});
    PerceptionSettings& p = s.perception;
    p.enabled = n->boolean("enabled", true);
    const std::string profile = n->has("profile") ? (*n)["profile"].string() : "ideal";
    if (profile != "ideal" && profile != "realistic")
      n->failKey("profile", "must be ideal or realistic");
    p.realistic = profile == "realistic";
    for (auto [key, value] :
         {std::pair{"ball_range", &p.ball_range}, std::pair{"post_range", &p.post_range},
          std::pair{"robot_range", &p.robot_range}, std::pair{"distance_noise", &p.distance_noise},
          std::pair{"bearing_noise", &p.bearing_noise}, std::pair{"miss_base", &p.miss_base},
          std::pair{"miss_per_metre", &p.miss_per_metre},
          std::pair{"false_ball_rate", &p.false_ball_rate},
          std::pair{"pose_noise_xy", &p.pose_noise_xy},
          std::pair{"pose_noise_yaw", &p.pose_noise_yaw},
          std::pair{"pose_noise_time", &p.pose_noise_time}})
      if (n->has(key)) *value = (*n)[key].nonNegative();
    for (auto [key, value] :
         {std::pair{"miss_base", p.miss_base}, std::pair{"false_ball_rate", p.false_ball_rate}})
      if (value > 1.0) n->failKey(key, "a probability: 0..1");
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
      if (p.number < 1 || p.number > static_cast<int>(protocol::kMaxPlayers))
        n.failKey("number", kPlayerNumbers);
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

int solverThreads(const PhysicsConfig& physics) {
  if (physics.threads > 0) return physics.threads;
  // The cores this process may run on (a container or `taskset` may allow
  // fewer than the machine has).
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  const int n = sched_getaffinity(0, sizeof cpus, &cpus) == 0
                    ? CPU_COUNT(&cpus)
                    : static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(n, 1, 4);
}

}  // namespace simsoccer::world

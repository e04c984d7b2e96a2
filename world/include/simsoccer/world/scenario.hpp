// A world scenario: which field and robot models, where the robots and the
// ball start, physics settings and the seed. Loaded from YAML (see
// configs/) or built in code (the benchmarks), validated either way.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::world {

struct RobotPlacement {
  int team = 0;                   // 0 or 1
  int number = 1;                 // player number, unique within a team
  double x = 0.0, y = 0.0;        // m, field frame
  double yaw = 0.0;               // rad, heading in the field frame
  std::string posture = "stand";  // named pose of the robot model
  std::string model_file;         // empty: the scenario's robot_model
};

struct PhysicsConfig {
  // The project's default step: one physics step per control period. The
  // robot models' servos are implicit where their explicit servo is not
  // stable at it (Motor::explicit_up_to).
  double dt = 0.010;              // s
  double control_period = 0.010;  // s, a whole multiple of dt
  int solver_iterations = 10;
  // Gauss-Seidel sweeps over the joint rows (implicit servos, joint limits,
  // gears) in each solver iteration, the contacts swept once. A joint row
  // costs one coordinate, a contact a whole robot's. At a 10 ms step one
  // sweep leaves the legs' servos unconverged (the Nao's walk drifts and
  // slows to 0.19 m/s, kicks fall short, get-ups fail): two, the default,
  // keep every figure (at 5 ms one is enough; a second costs 2.5 % there).
  int joint_sweeps = 2;
  // Each contact's rows start the solver from this share of its point's
  // impulses of the last step (normal and friction; 0: from zero, as
  // Bullet's multibody contacts). Resting contacts then converge across
  // steps: at 10 ms without it a standing Nao rocked 4 deg and leaned 0.9,
  // with it 0.5 and 0.4, as at 5 ms.
  double contact_warm_start = 1.0;
  // Friction rows per contact: 2 (a pyramid; the default) or 1. With 1,
  // Bullet gives a multibody contact a single row along a fixed tangent
  // (btPlaneSpace1 of the normal: the y axis on flat ground), not along the
  // slip: feet hold sideways but slide freely forward and back, so robots
  // cannot walk. Kept for comparisons only.
  int friction_directions = 2;
  // true: Bullet's own contact rows and solver iterations throughout, for
  // comparisons; false (the default): the engine's (engine/src/
  // articulation_solver.hpp), the same physics up to rounding, faster.
  bool bullet_solver = false;
  // true (the default): an implicit servo's torque is bounded by its motor's
  // torque-speed line at the joint speed the solver finds; false: by bounds
  // predicted before the step (as with bullet_solver), for comparisons.
  bool envelope_in_solver = true;
  // true (the default): robot links clearly above the ground skip Bullet's narrowphase with
  // it (the same state bit for bit); false: Bullet's for every link, for comparisons.
  bool cull_ground_pairs = true;
  double gravity = -9.81;  // m/s^2 along z
  // Threads that solve the constraint batches (groups of robots and what
  // touches them) side by side; 0 (`auto`, the default): see solverThreads().
  // The result is the same bit for bit for any number.
  int threads = 0;
  static constexpr int kMaxThreads = 64;
};

// The solver threads a world of this physics uses: `threads`, or with auto
// one per core this process may run on, at most 4 (a step of 22 robots has
// about 6 batches, and the agents of a lockstep match wait while the physics
// steps).
int solverThreads(const PhysicsConfig& physics);

// Standard deviations of the seeded random perturbations applied when the
// robots are placed (0 = exact placement).
struct PlacementNoise {
  double position = 0.0;  // m
  double yaw = 0.0;       // rad
  double joints = 0.0;    // rad
};

// Sensor simulation settings (the hardware's own numbers are in the robot
// model). Noise is white, per axis, from the scenario seed; off by default.
struct SensorSettings {
  bool enabled = true;          // false: no sensor frames (pure physics runs)
  int sonar_rays = 9;           // rays per sonar cone
  double sonar_period = 0.060;  // s between sonar updates, a multiple of the control period
  engine::Vec3 gyro_noise = engine::Vec3::Zero();   // rad/s std dev
  engine::Vec3 gyro_bias = engine::Vec3::Zero();    // rad/s
  engine::Vec3 accel_noise = engine::Vec3::Zero();  // m/s^2 std dev
  engine::Vec3 accel_bias = engine::Vec3::Zero();   // m/s^2
  engine::Vec3 angle_noise = engine::Vec3::Zero();  // rad std dev (roll, pitch, yaw)
};

// One kind of robot camera (all robots' top cameras, or bottom cameras).
struct CameraSpec {
  bool enabled = true;
  int width = 640, height = 480;  // px (width even: YUYV pairs pixels)
  double rate = 30.0;             // Hz, at most one image per control period
};

// A fixed camera looking at the match (for video).
struct SpectatorSpec {
  bool enabled = false;
  engine::Vec3 position{0.0, -6.5, 4.0};  // m, field frame
  engine::Vec3 look_at{0.0, 0.0, 0.0};    // m, field frame
  int width = 960, height = 540;          // px
  double horizontal_fov = 1.22;           // rad (70 deg)
  double rate = 30.0;                     // Hz
};

// A robot camera's mounting error: a rotation of the camera frame (roll
// about x, pitch about y, yaw about z, rad) after the model's pose.
struct CameraCalibration {
  int team = 0, number = 1;
  std::string camera = "top";  // top | bottom
  engine::Vec3 rpy = engine::Vec3::Zero();
};

// Image effects, all off (0) by default.
struct CameraEffects {
  double noise = 0.0;                    // Gaussian noise std dev, 8-bit levels
  double motion_blur_exposure = 0.0;     // s of exposure blurring the image's motion
  double rolling_shutter_readout = 0.0;  // s from the first row to the last (V6: rows in turn)
};

// Off-screen cameras: off unless a scenario turns them on.
struct CameraSettings {
  bool enabled = false;
  CameraSpec top{true, 640, 480, 30.0};
  CameraSpec bottom{true, 320, 240, 30.0};
  std::string encoding = "yuyv";  // yuyv | jpeg
  int jpeg_quality = 85;
  int queue = 2;  // captures waiting or being rendered before the policy applies
  CameraEffects effects;
  std::vector<CameraCalibration> calibration;
  SpectatorSpec spectator;
};

// The geometric perception the simulator publishes to agents (world/perception.hpp).
struct PerceptionSettings {
  bool enabled = false;
  bool realistic = false;          // profile: ideal (false) or realistic
  double ball_range = 6.0;         // m (realistic)
  double post_range = 9.0;         // m
  double robot_range = 6.0;        // m
  double distance_noise = 0.05;    // std dev as a fraction of the distance
  double bearing_noise = 0.02;     // rad std dev
  double miss_base = 0.02;         // probability of not seeing a visible object...
  double miss_per_metre = 0.04;    // ...growing with distance
  double false_ball_rate = 0.005;  // per control period
  double pose_noise_xy = 0.05;     // m std dev of the self-pose estimate (realistic)
  double pose_noise_yaw = 0.03;    // rad
  // s: how long the self-pose error takes to wander off (its correlation time). A localisation
  // filter's estimate is off by a drifting amount, not by a fresh sample each period; 0 gives
  // white noise (every period a new, independent error).
  double pose_noise_time = 1.0;
};

struct Scenario {
  std::string name;
  std::string source_file;  // for error messages; empty when built in code
  std::filesystem::path field_file;
  std::filesystem::path robot_model_file;
  PhysicsConfig physics;
  uint64_t seed = 1;
  PlacementNoise noise;
  SensorSettings sensors;
  CameraSettings cameras;
  PerceptionSettings perception;
  engine::Vec3 ball_position{0.0, 0.0, -1.0};  // z < 0: resting on the ground
  engine::Vec3 ball_velocity = engine::Vec3::Zero();
  std::vector<RobotPlacement> robots;
};

// Reads and checks a scenario file (syntax, types, required keys).
// Model-dependent checks (placement on the field, postures) run when the
// World is built. Throws engine::ConfigError.
Scenario loadScenario(const std::filesystem::path& file);

}  // namespace simsoccer::world

#include "simsoccer/world/camera_system.hpp"

#include <chrono>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/world/render_scene.hpp"

namespace simsoccer::world {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Angular velocity (world frame) of a robot link: the root's plus every joint
// on the way up, each about its axis as the parent link holds it now.
Vec3 linkAngularVelocity(const World& world, RobotId r, int link) {
  const RobotInfo& info = world.robot(r);
  const auto& body = *info.model->body;
  Vec3 omega = world.physics().rootAngularVelocity(info.body);
  for (int l = link; l > 0;) {
    const int j = l - 1;  // joint j moves link j + 1
    const engine::Joint& joint = body.joints[static_cast<size_t>(j)];
    omega += world.linkPose(r, joint.parent_link).linear() * joint.axis *
             world.physics().jointVelocity(info.body, j);
    l = joint.parent_link;
  }
  return omega;
}

}  // namespace

bool CameraSystem::due(uint64_t tick, double control_period, double rate) {
  if (tick == 0) return true;
  // Image k is due at the first period at or after k / rate; the small
  // offset keeps exact multiples (30 Hz at 100 Hz control) from rounding down.
  const auto images = [&](uint64_t t) {
    return std::floor(static_cast<double>(t) * control_period * rate + 1e-9);
  };
  return images(tick) != images(tick - 1);
}

CameraSystem::CameraSystem(const World& world, const CameraSettings& settings, BehindPolicy policy,
                           Sink sink)
    : settings_(settings),
      policy_(policy),
      sink_(std::move(sink)),
      seed_(world.scenario().seed),
      control_period_(world.scenario().physics.control_period) {
  calibration_.assign(2 * world.robotCount(), engine::Pose::Identity());
  for (const CameraCalibration& c : settings_.calibration) {
    bool found = false;
    for (RobotId r = 0; r < world.robotCount(); ++r) {
      if (world.robot(r).team != c.team || world.robot(r).number != c.number) continue;
      engine::Pose& p = calibration_[2 * r + (c.camera == "bottom" ? 1 : 0)];
      p = engine::Pose::Identity();
      p.rotate(Eigen::AngleAxisd(c.rpy.z(), Vec3::UnitZ()) *
               Eigen::AngleAxisd(c.rpy.y(), Vec3::UnitY()) *
               Eigen::AngleAxisd(c.rpy.x(), Vec3::UnitX()));
      found = true;
    }
    if (!found)
      throw engine::ConfigError(world.scenario().source_file, "cameras.calibration",
                                "no robot team " + std::to_string(c.team) + " number " +
                                    std::to_string(c.number) + " in the scenario");
  }
  // A robot's first camera takes the `top` settings, its second the `bottom`
  // ones (a Nao: CameraTop, CameraBottom); a robot with one camera (a
  // Booster K1's head camera) has no second view.
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    const robots::RobotModel& model = *world.robot(r).model;
    if (model.cameraCount() == 0)
      throw engine::ConfigError(world.scenario().source_file, "cameras",
                                "robot model " + model.name + " has no camera");
    std::array<const robots::SensorFrame*, 2> slots{};
    for (size_t c = 0; c < model.cameraCount() && c < 2; ++c) slots[c] = &model.camera(c);
    cameras_.push_back(slots);
  }
  thread_ = std::thread([this] { run(); });
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return started_; });
  if (!start_error_.empty()) {
    lock.unlock();
    thread_.join();
    throw engine::RenderError(start_error_);
  }
  lock.unlock();
  convert_thread_ = std::thread([this] { convert(); });
}

CameraSystem::~CameraSystem() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (convert_thread_.joinable()) convert_thread_.join();
}

void CameraSystem::capture(const World& world) {
  const uint64_t tick = world.controlTick();
  const std::array<const CameraSpec*, 2> specs{&settings_.top, &settings_.bottom};
  std::array<bool, 2> robot_due{};
  for (size_t c = 0; c < 2; ++c)
    robot_due[c] = specs[c]->enabled && due(tick, control_period_, specs[c]->rate);
  const bool spectator_due =
      settings_.spectator.enabled && due(tick, control_period_, settings_.spectator.rate);
  if (!robot_due[0] && !robot_due[1] && !spectator_due) return;

  {
    std::unique_lock lock(mutex_);
    const auto full = [&] { return queue_.size() >= static_cast<size_t>(settings_.queue); };
    if (full()) {
      if (policy_ == BehindPolicy::Drop) {
        ++stats_.dropped;
        return;
      }
      const auto t0 = Clock::now();
      changed_.wait(lock, [&] { return !full(); });
      stats_.wait_ms += msSince(t0);
    }
  }
  Job job;
  job.tick = tick;
  job.sim_time = world.time();
  buildRenderScene(world, job.scene);
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    const RobotInfo& info = world.robot(r);
    for (size_t c = 0; c < 2; ++c) {
      const robots::SensorFrame* s = cameras_[r][c];
      if (!robot_due[c] || !s) continue;
      const engine::Pose pose = world.linkPose(r, s->link) * s->pose * calibration_[2 * r + c];
      ViewJob v{static_cast<CameraId>(c),
                r,
                info.team,
                info.number,
                engine::pinholeView(pose, specs[c]->width, specs[c]->height, s->horizontal_fov,
                                    s->vertical_fov),
                Vec3::Zero()};
      v.view.format = robotFormat();
      const auto& e = settings_.effects;
      if (e.motion_blur_exposure > 0 || e.rolling_shutter_readout > 0)
        v.angular_velocity = pose.linear().transpose() * linkAngularVelocity(world, r, s->link);
      job.views.push_back(v);
    }
  }
  if (spectator_due) {
    const SpectatorSpec& sp = settings_.spectator;
    const double vertical_fov =
        2 * std::atan(std::tan(0.5 * sp.horizontal_fov) * sp.height / sp.width);
    job.views.push_back({CameraId::Spectator, 0, 0, 0,
                         engine::pinholeView(lookAtPose(sp.position, sp.look_at), sp.width,
                                             sp.height, sp.horizontal_fov, vertical_fov),
                         Vec3::Zero()});
  }
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(job));
  }
  changed_.notify_all();
}

void CameraSystem::flush() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.empty(); });
}

engine::PixelFormat CameraSystem::robotFormat() const {
  return settings_.encoding == "yuyv" && settings_.effects.noise == 0 ? engine::PixelFormat::Yuv
                                                                      : engine::PixelFormat::Rgb;
}

CameraStats CameraSystem::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void CameraSystem::run() {
  std::unique_ptr<engine::OffscreenRenderer> renderer;
  try {
    renderer = std::make_unique<engine::OffscreenRenderer>();
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    start_error_ = e.what();
    started_ = true;
    changed_.notify_all();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    gl_renderer_ = renderer->glRenderer();
    started_ = true;
  }
  changed_.notify_all();
  std::vector<engine::RenderView> views;
  for (;;) {
    Job* job = nullptr;
    {
      std::unique_lock lock(mutex_);
      // The front job is being converted while converting_ holds it; the
      // next one is this thread's.
      const auto rendered = [&] { return converting_ ? size_t{1} : size_t{0}; };
      changed_.wait(lock, [&] { return stopping_ || rendered() < queue_.size(); });
      if (rendered() == queue_.size()) {  // stopping, everything rendered
        render_done_ = true;
        changed_.notify_all();
        return;
      }
      job = &queue_[rendered()];  // stays queued until delivered
    }
    views.clear();
    for (const ViewJob& v : job->views) views.push_back(v.view);
    renderer->render(job->scene, views);
    Rendered rendered{job, {}, renderer->lastTiming()};
    for (size_t i = 0; i < views.size(); ++i) rendered.pixels.push_back(renderer->image(i));
    {
      // The previous capture must be converted before this one is handed
      // over: the render after this one reuses that capture's readback buffer.
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !converting_.has_value(); });
      converting_ = std::move(rendered);
    }
    changed_.notify_all();
  }
}

void CameraSystem::convert() {
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return converting_.has_value() || render_done_; });
      if (!converting_) return;  // the render thread has stopped and everything is delivered
    }
    // Only this thread touches converting_ while it holds a capture.
    process(*converting_);
    {
      std::lock_guard lock(mutex_);
      converting_.reset();
      queue_.pop_front();
    }
    changed_.notify_all();
  }
}

void CameraSystem::process(Rendered& rendered) {
  const Job& job = *rendered.job;
  const engine::RenderTiming& timing = rendered.timing;
  double convert_ms = 0.0, deliver_ms = 0.0;
  uint64_t pixels = 0;
  CameraImage image;
  for (size_t i = 0; i < job.views.size(); ++i) {
    const ViewJob& v = job.views[i];
    const auto t0 = Clock::now();
    cv::Mat drawn = rendered.pixels[i];  // RGBA, or YUVA (v.view.format)
    pixels += drawn.total();
    image.camera = v.camera;
    image.robot = v.robot;
    image.team = v.team;
    image.number = v.number;
    image.tick = job.tick;
    image.sim_time = job.sim_time;
    image.view = v.view;
    image.bgr.release();  // (image.data keeps its capacity from view to view)
    if (v.camera == CameraId::Spectator) {
      image.encoding = ImageEncoding::Bgr;
      image.data.clear();
      cv::cvtColor(drawn, image.bgr, cv::COLOR_RGBA2BGR);
    } else {
      // Noise seeded per scenario, capture, robot and camera: the same run, the same noise.
      const uint64_t key =
          seed_ * 0x9E3779B97F4A7C15ULL ^ (job.tick * 0xBF58476D1CE4E5B9ULL) ^
          ((static_cast<uint64_t>(v.robot) << 1 | static_cast<uint64_t>(v.camera)) *
           0x94D049BB133111EBULL);
      // Blur and the rolling shutter move and mix pixels, the same in YUV as in RGB.
      applyCameraEffects(drawn, settings_.effects, v.view, v.angular_velocity, key);
      if (settings_.encoding == "jpeg") {
        image.encoding = ImageEncoding::Jpeg;
        cv::Mat bgr;
        cv::cvtColor(drawn, bgr, cv::COLOR_RGBA2BGR);
        cv::imencode(".jpg", bgr, image.data, {cv::IMWRITE_JPEG_QUALITY, settings_.jpeg_quality});
      } else {
        image.encoding = ImageEncoding::Yuyv;
        image.data.resize(drawn.total() * 2);
        cv::Mat yuyv(drawn.rows, drawn.cols, CV_8UC2,
                     image.data.data());  // straight into the image
        if (v.view.format == engine::PixelFormat::Yuv)
          engine::yuvToYuyv(drawn, yuyv);
        else
          engine::rgbToYuyv(drawn, yuyv);
      }
    }
    convert_ms += msSince(t0);
    const auto t1 = Clock::now();
    if (sink_) sink_(image);
    deliver_ms += msSince(t1);
  }
  std::lock_guard lock(mutex_);
  ++stats_.captures;
  stats_.views += job.views.size();
  stats_.pixels += pixels;
  stats_.draw_ms += timing.draw_ms;
  stats_.readback_ms += timing.readback_ms;
  stats_.convert_ms += convert_ms;
  stats_.deliver_ms += deliver_ms;
  stats_.triangles = timing.triangles;
  stats_.last_views = job.views.size();
}

void applyCameraEffects(cv::Mat& rgba, const CameraEffects& e, const engine::RenderView& view,
                        const Vec3& angular_velocity, uint64_t noise_key) {
  // Image motion from the camera's rotation (camera frame x forward, y left,
  // z up): turning left (+z) moves the scene right, pitching down (+y) moves it up.
  const double du_dt = view.fx * angular_velocity.z();
  const double dv_dt = -view.fy * angular_velocity.y();
  if (e.rolling_shutter_readout > 0 && (du_dt != 0 || dv_dt != 0)) {
    // Row r is read (r / height - 1/2) * readout after the middle row, when
    // the scene had moved on by that time times the image velocity.
    cv::Mat map_x(rgba.rows, rgba.cols, CV_32F), map_y(rgba.rows, rgba.cols, CV_32F);
    for (int r = 0; r < rgba.rows; ++r) {
      const double t = (static_cast<double>(r) / rgba.rows - 0.5) * e.rolling_shutter_readout;
      auto* mx = map_x.ptr<float>(r);
      auto* my = map_y.ptr<float>(r);
      for (int c = 0; c < rgba.cols; ++c) {
        mx[c] = static_cast<float>(c - du_dt * t);
        my[c] = static_cast<float>(r - dv_dt * t);
      }
    }
    cv::Mat out;
    cv::remap(rgba, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    rgba = out;
  }
  if (e.motion_blur_exposure > 0) {
    // A line kernel as long as the image moves during the exposure.
    const double dx = du_dt * e.motion_blur_exposure, dy = dv_dt * e.motion_blur_exposure;
    const double length = std::hypot(dx, dy);
    if (length >= 1.0) {
      const int half = static_cast<int>(std::ceil(0.5 * length));
      cv::Mat kernel = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
      const cv::Point2d centre(half, half), d(0.5 * dx, 0.5 * dy);
      cv::line(kernel, centre - d, centre + d, cv::Scalar(1.0), 1, cv::LINE_AA);
      kernel /= cv::sum(kernel)[0];
      cv::Mat out;
      cv::filter2D(rgba, out, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
      rgba = out;
    }
  }
  if (e.noise > 0) {
    cv::RNG rng(noise_key);
    cv::Mat noise(rgba.size(), CV_16SC(rgba.channels()));
    rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar(e.noise, e.noise, e.noise, 0));
    cv::Mat out;
    cv::add(rgba, noise, out, cv::noArray(), rgba.type());  // saturating
    rgba = out;
  }
}

}  // namespace simsoccer::world

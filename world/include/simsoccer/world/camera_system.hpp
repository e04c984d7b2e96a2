// Every robot's cameras (and the spectator's) rendered off the simulation
// thread. At each control period the simulation thread calls capture(): if a
// camera is due, it copies the scene and the due views (a few kB) into a job
// on a bounded queue; the render thread, which owns the EGL context, draws all
// views of a job in one batch and reads them back; the conversion thread
// applies the image effects, converts each view (YUYV or JPEG; BGR for the
// spectator) and hands it to the sink while the next job is drawn.
//
// When rendering falls behind (the queue holds `queue` captures):
//   Wait  - capture() blocks until there is room (lockstep: nothing is lost,
//           and the images of capture c are delivered before capture
//           c + queue is taken, whatever the machine's speed);
//   Drop  - the new capture is dropped and counted (real time).
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/world/scenario.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::world {

enum class CameraId : uint8_t { Top = 0, Bottom = 1, Spectator = 2 };
enum class ImageEncoding : uint8_t { Yuyv = 0, Jpeg = 1, Bgr = 2 };
enum class BehindPolicy { Wait, Drop };

// One delivered image.
struct CameraImage {
  CameraId camera = CameraId::Top;
  RobotId robot = 0;         // robot cameras only
  int team = 0, number = 0;  // robot cameras only
  uint64_t tick = 0;         // control period of the capture
  double sim_time = 0.0;     // s
  engine::RenderView view;   // pose (field frame; x forward, y left, z up) and intrinsics
  ImageEncoding encoding = ImageEncoding::Yuyv;
  std::vector<uint8_t> data;  // YUYV (width * height * 2 bytes) or a JPEG file
  cv::Mat bgr;                // the spectator's image (CV_8UC3), empty otherwise
};

struct CameraStats {
  uint64_t captures = 0;  // jobs rendered
  uint64_t views = 0;     // images delivered
  uint64_t dropped = 0;   // captures dropped (Drop policy)
  uint64_t pixels = 0;    // rendered
  double draw_ms = 0.0;   // summed over jobs: drawing (render thread)
  double readback_ms = 0.0;
  double convert_ms = 0.0;  // effects + YUYV/JPEG/BGR conversion
  double deliver_ms = 0.0;  // in the sink
  double wait_ms = 0.0;     // the simulation thread blocked in capture() (Wait policy)
  size_t triangles = 0;     // drawn in the last job, all views together
  size_t last_views = 0;    // views in the last job
};

// The optional image effects on one 8-bit RGB(A) view, in place: rolling
// shutter (rows read in turn over the readout time while the camera turns at
// `angular_velocity`, camera frame x forward, y left, z up, rad/s), motion blur
// along the image motion during the exposure, and Gaussian noise drawn from
// `noise_key` (the same key gives the same noise).
void applyCameraEffects(cv::Mat& image, const CameraEffects& effects,
                        const engine::RenderView& view, const Vec3& angular_velocity,
                        uint64_t noise_key);

class CameraSystem {
 public:
  // Called on the conversion thread, in capture order, once per image.
  using Sink = std::function<void(const CameraImage&)>;

  // Starts the render thread (with its EGL context) and the conversion
  // thread, which converts and delivers one capture's images while the next
  // capture is drawn; throws engine::RenderError
  // if the context cannot be made, engine::ConfigError if the settings name a
  // robot that is not in the world.
  CameraSystem(const World& world, const CameraSettings& settings, BehindPolicy policy, Sink sink);
  ~CameraSystem();  // delivers what is queued, then stops the threads
  CameraSystem(const CameraSystem&) = delete;
  CameraSystem& operator=(const CameraSystem&) = delete;

  // After a control period: queues the cameras due at the world's current tick.
  void capture(const World& world);
  // Blocks until every queued capture has been delivered.
  void flush();
  CameraStats stats() const;
  std::string glRenderer() const { return gl_renderer_; }

  // Whether a camera at `rate` Hz takes an image at control period `tick`
  // (`rate` images per simulated second, the first at tick 0).
  static bool due(uint64_t tick, double control_period, double rate);

 private:
  struct ViewJob {
    CameraId camera;
    RobotId robot;
    int team, number;
    engine::RenderView view;
    Vec3 angular_velocity;  // camera frame, rad/s (effects)
  };
  struct Job {
    uint64_t tick = 0;
    double sim_time = 0.0;
    std::vector<engine::DrawItem> scene;
    std::vector<ViewJob> views;
  };

  // A rendered capture on its way to conversion: its views' four-channel
  // pixels (RGBA, or YUVA for a view drawn in YUV; regions of one of the
  // renderer's two readback buffers) and timings.
  struct Rendered {
    Job* job = nullptr;
    std::vector<cv::Mat> pixels;
    engine::RenderTiming timing;
  };

  void run();      // render thread
  void convert();  // conversion thread
  void process(Rendered& rendered);
  // Robot cameras are drawn in YUV when they deliver YUYV without noise (the
  // noise is given per RGB channel), so their images need only packing.
  engine::PixelFormat robotFormat() const;

  CameraSettings settings_;
  BehindPolicy policy_;
  Sink sink_;
  uint64_t seed_;
  double control_period_;
  std::vector<engine::Pose>
      calibration_;  // per robot * 2 (top, bottom): camera from calibrated camera
  // Per robot: its first and second camera of the model (null: none).
  std::vector<std::array<const robots::SensorFrame*, 2>> cameras_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  // Waiting and in flight, oldest first: while converting_ holds the front
  // one's capture, the render thread works on the second.
  std::deque<Job> queue_;
  std::optional<Rendered> converting_;  // handed to the conversion thread
  bool render_done_ = false;            // the render thread has returned
  bool stopping_ = false;
  std::string start_error_;
  bool started_ = false;
  CameraStats stats_;
  std::string gl_renderer_;
  std::thread thread_, convert_thread_;
};

}  // namespace simsoccer::world

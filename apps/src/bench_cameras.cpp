// simsoccer bench cameras: both cameras of every robot rendered at their
// rates while the physics runs, through the same CameraSystem a match uses
// (render thread, bounded queue, lockstep's Wait policy).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/world/camera_system.hpp"

namespace simsoccer::apps {
namespace {

const char* kBenchCamerasHelp =
    "usage: simsoccer bench cameras [--config FILE] [--robots 1,2,4,8,11,22] [--seconds S]\n"
    "                               [--rate HZ] [--encoding yuyv|jpeg] [--csv FILE]\n"
    "\n"
    "The physics benchmark's scene (N Naos in pairs, joints and heads moving) with every\n"
    "robot's top (640x480) and bottom (320x240) camera on at 30 Hz, or the scenario's own\n"
    "`cameras:` block if it has one. Runs S simulated seconds per N: the simulation thread\n"
    "steps the physics and queues each due capture; the render thread (EGL, one batched\n"
    "framebuffer per capture) draws and reads back every view, the conversion thread converts\n"
    "them while the next capture is drawn. Lockstep policy: the\n"
    "simulation waits when two captures are queued, so nothing is dropped.\n"
    "Prints per N: views, views per wall second, ms per batched frame (draw), ms readback and\n"
    "ms conversion per frame, the real-time factor with cameras on and with them off (same\n"
    "scene, physics alone), triangles per view after culling, and image bytes per simulated s.\n"
    "\n"
    "  --config FILE     benchmark scenario (default configs/bench/physics.yaml)\n"
    "  --robots LIST     robot counts (default from the config)\n"
    "  --seconds S       simulated seconds timed per robot count (default 10)\n"
    "  --rate HZ         both cameras' rate (default 30, or the scenario's)\n"
    "  --encoding E      yuyv (default, the Nao's format) or jpeg\n"
    "  --csv FILE        also write the table as CSV (one row per robot count)\n";

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int benchCameras(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"},
                    {"config", "robots", "seconds", "rate", "encoding", "csv"});
  if (opt.help(kBenchCamerasHelp)) return 0;
  opt.noPositional();
  const auto config_file = findConfig(opt.get("config", ""), "configs/bench/physics.yaml");
  const BenchConfig cfg = loadBenchConfig(config_file);
  const std::vector<int> counts = opt.intList("robots", cfg.robots);
  const double seconds = opt.positive("seconds", 10.0);
  if (!(seconds > 0)) throw UsageError("--seconds must be > 0");
  world::CameraSettings cameras = cfg.base.cameras;
  cameras.enabled = true;
  if (opt.has("rate")) {
    const double rate = opt.number("rate", 30.0);
    if (!(rate > 0) || rate * cfg.base.physics.control_period > 1.0 + 1e-9)
      throw UsageError("--rate must be > 0 and at most one image per control period");
    cameras.top.rate = cameras.bottom.rate = rate;
  }
  cameras.encoding = opt.get("encoding", cameras.encoding);
  if (cameras.encoding != "yuyv" && cameras.encoding != "jpeg")
    throw UsageError("--encoding must be yuyv or jpeg");
  cameras.spectator.enabled = false;
  const std::string csv = opt.get("csv", "");
  const fields::FieldModel field = fields::loadFieldModel(cfg.base.field_file);

  std::printf(
      "simsoccer bench cameras: %s, top %dx%d @ %.0f Hz, bottom %dx%d @ %.0f Hz, %s, %.0f s "
      "simulated per row\n",
      config_file.string().c_str(), cameras.top.width, cameras.top.height, cameras.top.rate,
      cameras.bottom.width, cameras.bottom.height, cameras.bottom.rate, cameras.encoding.c_str(),
      seconds);
  std::fflush(stdout);

  Table table;
  table.header = {
      "robots",     "views",       "views_per_s",      "ms_per_frame",       "ms_readback",
      "ms_convert", "rtf_cameras", "rtf_physics_only", "triangles_per_view", "mbytes_per_sim_s",
      "dropped"};
  std::string gl_renderer;
  for (const int n : counts) {
    const world::Scenario scenario = placeRobots(cfg, n, field.halfLength(), field.halfWidth());
    const auto periods = static_cast<long>(seconds / scenario.physics.control_period);
    const auto settle = static_cast<long>(cfg.settle / scenario.physics.control_period);
    // Physics alone, the same scene and motion.
    double rtf_physics = 0.0;
    {
      world::World w(scenario);
      const BenchMotion motion(cfg, w);
      for (long i = 0; i < settle; ++i) {
        motion.command(w);
        w.stepControlPeriod();
      }
      const auto t0 = Clock::now();
      for (long i = 0; i < periods; ++i) {
        motion.command(w);
        w.stepControlPeriod();
      }
      rtf_physics = seconds / secondsSince(t0);
    }
    world::World w(scenario);
    const BenchMotion motion(cfg, w);
    for (long i = 0; i < settle; ++i) {
      motion.command(w);
      w.stepControlPeriod();
    }
    uint64_t bytes = 0;  // touched on the conversion thread only, read after flush()
    world::CameraSystem system(
        w, cameras, world::BehindPolicy::Wait,
        [&](const world::CameraImage& image) { bytes += image.data.size(); });
    gl_renderer = system.glRenderer();
    const auto t0 = Clock::now();
    for (long i = 0; i < periods; ++i) {
      motion.command(w);
      w.stepControlPeriod();
      system.capture(w);
    }
    system.flush();
    const double wall = secondsSince(t0);
    const world::CameraStats st = system.stats();
    const double frames = static_cast<double>(std::max<uint64_t>(st.captures, 1));
    table.rows.push_back(
        {std::to_string(n), std::to_string(st.views), fmt(static_cast<double>(st.views) / wall, 1),
         fmt(st.draw_ms / frames, 1), fmt(st.readback_ms / frames, 1),
         fmt(st.convert_ms / frames, 1), fmt(seconds / wall, 2), fmt(rtf_physics, 2),
         std::to_string(st.last_views ? st.triangles / st.last_views : 0),
         fmt(static_cast<double>(bytes) / seconds / 1e6, 1), std::to_string(st.dropped)});
    std::fprintf(stderr, "  %d robots done\n", n);
  }
  table.finish("renderer: " + gl_renderer +
                   ". views = images delivered; ms per batched frame (all views of one capture): "
                   "draw, readback, conversion (effects + " +
                   cameras.encoding +
                   "); rtf = simulated / wall time with cameras on and with physics alone; "
                   "triangles per view drawn after frustum culling (last frame).",
               csv);
  return 0;
}

}  // namespace simsoccer::apps

// TEMP quick render timing
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include "bench_scene.hpp"
#include "cli.hpp"
#include "simsoccer/world/render_scene.hpp"
namespace simsoccer::apps {
int benchCameras(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help"}, {"config", "robots"});
  const auto config_file = findConfig(opt.get("config", ""), "configs/bench/physics.yaml");
  BenchConfig cfg = loadBenchConfig(config_file);
  const fields::FieldModel field = fields::loadFieldModel(cfg.base.field_file);
  engine::OffscreenRenderer renderer;
  for (int n : opt.intList("robots", cfg.robots)) {
    world::World w(placeRobots(cfg, n, field.halfLength(), field.halfWidth()));
    for (int i = 0; i < 50; ++i) w.stepControlPeriod();
    std::vector<engine::DrawItem> items;
    std::vector<engine::RenderView> views;
    std::vector<cv::Mat> images;
    double draw = 0, read = 0;
    for (int k = 0; k < 10; ++k) {
      items.clear(); views.clear();
      world::buildRenderScene(w, items);
      for (size_t r = 0; r < w.robotCount(); ++r) {
        views.push_back(world::robotCameraView(w, r, "CameraTop", 640, 480));
        views.push_back(world::robotCameraView(w, r, "CameraBottom", 320, 240));
      }
      renderer.render(items, views, images);
      if (k >= 2) { draw += renderer.lastTiming().draw_ms; read += renderer.lastTiming().readback_ms; }
    }
    std::printf("%d robots: %zu tris/view, draw %.1f ms, read %.1f ms per frame (%zu views)\n", n,
                renderer.lastTiming().triangles_per_view, draw / 8, read / 8, views.size());
  }
  return 0;
}
}

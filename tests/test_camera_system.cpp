// The camera pipeline: rates, the render thread and its queue policies,
// image effects, calibration offsets, encodings, determinism (real EGL).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/world/camera_system.hpp"
#include "simsoccer/world/render_scene.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Vec3;

namespace {

// Small images keep the tests quick; the pipeline is the same at 640x480.
world::CameraSettings smallCameras() {
  world::CameraSettings c;
  c.enabled = true;
  c.top = {true, 64, 48, 30.0};
  c.bottom = {true, 32, 24, 15.0};
  return c;
}

struct Collected {
  std::mutex mutex;
  std::vector<world::CameraImage> images;
  world::CameraSystem::Sink sink() {
    return [this](const world::CameraImage& i) {
      std::lock_guard lock(mutex);
      images.push_back(i);
    };
  }
};

// The Y (luma) plane of a YUYV image.
cv::Mat luma(const world::CameraImage& image) {
  cv::Mat yuyv(image.view.height, image.view.width, CV_8UC2,
               const_cast<uint8_t*>(image.data.data()));
  cv::Mat channels[2];
  cv::split(yuyv, channels);
  return channels[0].clone();
}

// One capture of the robots' cameras as `c` sets them and a 320x180 spectator view.
std::vector<world::CameraImage> oneCaptureWithSpectator(const world::World& w,
                                                        world::CameraSettings c) {
  c.spectator.enabled = true;
  c.spectator.width = 320;
  c.spectator.height = 180;
  Collected got;
  world::CameraSystem cameras(w, c, world::BehindPolicy::Wait, got.sink());
  cameras.capture(w);
  cameras.flush();
  return got.images;
}

}  // namespace

TEST(CameraSystem, DueAtTheCameraRate) {
  for (double rate : {30.0, 15.0, 10.0, 100.0, 7.0}) {
    int images = 0;
    for (uint64_t tick = 0; tick < 100; ++tick)
      images += world::CameraSystem::due(tick, 0.01, rate);
    EXPECT_EQ(images, static_cast<int>(std::ceil(rate - 1e-9))) << rate << " Hz";
  }
  // 30 Hz at 100 Hz control: ticks 0, 4, 7, 10, 14, ...
  EXPECT_TRUE(world::CameraSystem::due(4, 0.01, 30.0));
  EXPECT_FALSE(world::CameraSystem::due(5, 0.01, 30.0));
  EXPECT_TRUE(world::CameraSystem::due(10, 0.01, 30.0));
}

TEST(CameraSystem, DeliversEveryDueViewWithItsTickAndPose) {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  world::World w(test::scenario(2));
  Collected got;
  world::CameraSystem cameras(w, smallCameras(), world::BehindPolicy::Wait, got.sink());
  std::map<std::pair<uint64_t, int>, engine::Pose> expected;  // (tick, robot * 2 + camera)
  for (int i = 0; i <= 100; ++i) {
    if (i > 0) w.stepControlPeriod();
    const uint64_t tick = static_cast<uint64_t>(i);
    for (world::RobotId r = 0; r < 2; ++r) {
      if (world::CameraSystem::due(tick, 0.01, 30.0))
        expected[{tick, 2 * static_cast<int>(r)}] =
            world::robotCameraView(w, r, "CameraTop", 64, 48).pose;
      if (world::CameraSystem::due(tick, 0.01, 15.0))
        expected[{tick, 2 * static_cast<int>(r) + 1}] =
            world::robotCameraView(w, r, "CameraBottom", 32, 24).pose;
    }
    cameras.capture(w);
  }
  cameras.flush();
  EXPECT_EQ(got.images.size(), expected.size());
  EXPECT_EQ(expected.size(), 2u * (31 + 16));  // 1.01 s: ticks 0..100
  uint64_t last_tick = 0;
  for (const auto& image : got.images) {
    EXPECT_GE(image.tick, last_tick);  // capture order
    last_tick = image.tick;
    const int k = 2 * static_cast<int>(image.robot) + static_cast<int>(image.camera);
    const auto it = expected.find({image.tick, k});
    ASSERT_NE(it, expected.end()) << "unexpected image at tick " << image.tick;
    EXPECT_TRUE(image.view.pose.isApprox(it->second, 1e-12));
    EXPECT_EQ(image.encoding, world::ImageEncoding::Yuyv);
    EXPECT_EQ(image.data.size(), static_cast<size_t>(image.view.width * image.view.height * 2));
    EXPECT_EQ(image.team, w.robot(image.robot).team);
    EXPECT_EQ(image.number, w.robot(image.robot).number);
    EXPECT_NEAR(image.sim_time, 0.01 * static_cast<double>(image.tick), 1e-9);
  }
  const world::CameraStats st = cameras.stats();
  EXPECT_EQ(st.views, expected.size());
  EXPECT_EQ(st.dropped, 0u);
  std::printf("%llu captures, %llu views, draw %.2f ms per capture\n",
              static_cast<unsigned long long>(st.captures),
              static_cast<unsigned long long>(st.views), st.draw_ms / st.captures);
}

TEST(CameraSystem, RealTimeDropsAndCountsWhenRenderingFallsBehind) {
  world::World w(test::scenario(4));
  world::CameraSettings c = smallCameras();
  c.top = {true, 640, 480, 100.0};  // an image every period: more than llvmpipe keeps up with
  c.bottom.enabled = false;
  c.queue = 1;
  std::atomic<uint64_t> delivered{0};
  uint64_t dropped = 0;
  {
    world::CameraSystem cameras(w, c, world::BehindPolicy::Drop,
                                [&](const world::CameraImage&) { ++delivered; });
    for (int i = 0; i < 60; ++i) cameras.capture(w);  // no stepping: as fast as captures come
    cameras.flush();
    dropped = cameras.stats().dropped;
    EXPECT_EQ(cameras.stats().captures + dropped, 60u);
  }
  EXPECT_GT(dropped, 0u);
  EXPECT_EQ(delivered.load() + 4 * dropped, 4u * 60);
  // Lockstep's Wait policy never drops: every capture is delivered.
  delivered = 0;
  world::CameraSystem waiting(w, c, world::BehindPolicy::Wait,
                              [&](const world::CameraImage&) { ++delivered; });
  for (int i = 0; i < 10; ++i) waiting.capture(w);
  waiting.flush();
  EXPECT_EQ(delivered.load(), 40u);
  EXPECT_EQ(waiting.stats().dropped, 0u);
}

TEST(CameraSystem, SameStateAndSeedSameBytesNoiseIncluded) {
  world::CameraSettings c = smallCameras();
  c.effects.noise = 6.0;
  auto run = [&](uint64_t seed) {
    world::World w(test::scenario(2, seed));
    Collected got;
    world::CameraSystem cameras(w, c, world::BehindPolicy::Wait, got.sink());
    for (int i = 0; i < 10; ++i) {
      w.stepControlPeriod();
      cameras.capture(w);
    }
    cameras.flush();
    std::vector<uint8_t> all;
    for (const auto& i : got.images) all.insert(all.end(), i.data.begin(), i.data.end());
    return all;
  };
  const auto a = run(1), b = run(1), other = run(2);
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, other);  // another seed, other noise
}

TEST(CameraSystem, EffectsMoveBlurAndNoiseAsConfigured) {
  // A white vertical bar 4 px wide on grey, seen by a 640x480 camera.
  const engine::RenderView view = engine::pinholeView(engine::Pose::Identity(), 640, 480,
                                                      56.3 * M_PI / 180.0, 43.7 * M_PI / 180.0);
  cv::Mat clean(480, 640, CV_8UC4, cv::Scalar(100, 100, 100, 255));
  clean.colRange(318, 322).setTo(cv::Scalar(250, 250, 250, 255));
  auto barCentre = [](const cv::Mat& img, int row) {
    double sum = 0, weight = 0;
    for (int c = 0; c < img.cols; ++c) {
      const double excess = std::max(0.0, img.at<cv::Vec4b>(row, c)[0] - 100.0);
      sum += excess * c;
      weight += excess;
    }
    return sum / weight + 0.5;
  };
  const double yaw_rate = 1.0;  // rad/s, turning left: the scene moves right
  const double du_dt = view.fx * yaw_rate;

  world::CameraEffects shutter;
  shutter.rolling_shutter_readout = 0.030;
  cv::Mat skewed = clean.clone();
  world::applyCameraEffects(skewed, shutter, view, Vec3(0, 0, yaw_rate), 1);
  // Row r is read (r/480 - 1/2) * 30 ms after the middle row.
  for (int row : {10, 240, 470}) {
    const double t = (row / 480.0 - 0.5) * 0.030;
    EXPECT_NEAR(barCentre(skewed, row) - barCentre(clean, row), du_dt * t, 0.3) << "row " << row;
  }
  std::printf("rolling shutter at 1 rad/s yaw: top row %+.1f px, bottom row %+.1f px\n",
              barCentre(skewed, 0) - 320, barCentre(skewed, 479) - 320);

  world::CameraEffects blur;
  blur.motion_blur_exposure = 0.020;  // 20 ms at 1 rad/s: ~12 px of motion
  cv::Mat smeared = clean.clone();
  world::applyCameraEffects(smeared, blur, view, Vec3(0, 0, yaw_rate), 1);
  int wide_clean = 0, wide_blur = 0;
  for (int c = 0; c < 640; ++c) {
    wide_clean += clean.at<cv::Vec4b>(240, c)[0] > 101;
    wide_blur += smeared.at<cv::Vec4b>(240, c)[0] > 101;
  }
  EXPECT_NEAR(wide_blur - wide_clean, du_dt * 0.020, 3.0);
  EXPECT_LT(smeared.at<cv::Vec4b>(240, 320)[0], 200);  // the energy spread out
  EXPECT_NEAR(barCentre(smeared, 240), barCentre(clean, 240), 0.5);
  // No rotation, no blur.
  cv::Mat still = clean.clone();
  world::applyCameraEffects(still, blur, view, Vec3::Zero(), 1);
  EXPECT_EQ(cv::norm(still, clean, cv::NORM_INF), 0.0);

  world::CameraEffects noise;
  noise.noise = 5.0;
  cv::Mat noisy = clean.clone(), again = clean.clone(), other = clean.clone();
  world::applyCameraEffects(noisy, noise, view, Vec3::Zero(), 42);
  world::applyCameraEffects(again, noise, view, Vec3::Zero(), 42);
  world::applyCameraEffects(other, noise, view, Vec3::Zero(), 43);
  cv::Mat diff;
  cv::Mat channels[4];
  noisy.convertTo(diff, CV_32FC4);
  cv::Mat reference;
  clean.convertTo(reference, CV_32FC4);
  cv::split(diff - reference, channels);
  cv::Scalar mean, stddev;
  cv::meanStdDev(channels[0].colRange(0, 300), mean, stddev);
  EXPECT_NEAR(stddev[0], 5.0, 0.25);
  EXPECT_NEAR(mean[0], 0.0, 0.1);
  EXPECT_EQ(cv::countNonZero(channels[3]), 0);  // alpha untouched
  EXPECT_EQ(cv::norm(noisy, again, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(noisy, other, cv::NORM_INF), 0.0);
}

TEST(CameraSystem, HeadTurningSkewsTheRenderedImage) {
  // The angular velocity comes from the physics: spin the robot and compare.
  world::World w(test::scenario(1));
  world::CameraSettings c = smallCameras();
  c.top = {true, 320, 240, 30.0};
  c.bottom.enabled = false;
  auto capture = [&](double readout) {
    world::CameraSettings s = c;
    s.effects.rolling_shutter_readout = readout;
    Collected got;
    world::CameraSystem cameras(w, s, world::BehindPolicy::Wait, got.sink());
    cameras.capture(w);
    cameras.flush();
    return luma(got.images.at(0));
  };
  w.physics().setRootVelocity(w.robot(0).body, Vec3::Zero(), Vec3(0, 0, 2.0));
  const cv::Mat plain = capture(0.0), skewed = capture(0.030);
  EXPECT_GT(cv::norm(plain, skewed, cv::NORM_L1), 1000.0);
  w.physics().setRootVelocity(w.robot(0).body, Vec3::Zero(), Vec3::Zero());
  EXPECT_EQ(cv::norm(capture(0.0), capture(0.030), cv::NORM_INF), 0.0);  // still: no skew
}

TEST(CameraSystem, CalibrationOffsetTurnsTheCamera) {
  world::World w(test::scenario(1));
  world::CameraSettings c = smallCameras();
  c.bottom.enabled = false;
  c.calibration.push_back({0, 1, "top", Vec3(0.0, 0.0, 0.05)});  // 0.05 rad yaw
  Collected got;
  world::CameraSystem cameras(w, c, world::BehindPolicy::Wait, got.sink());
  cameras.capture(w);
  cameras.flush();
  const engine::Pose nominal = world::robotCameraView(w, 0, "CameraTop", 64, 48).pose;
  const engine::Pose actual = got.images.at(0).view.pose;
  const Eigen::AngleAxisd offset(nominal.linear().transpose() * actual.linear());
  EXPECT_NEAR(offset.angle(), 0.05, 1e-9);
  EXPECT_NEAR(std::abs(offset.axis().z()), 1.0, 1e-9);
  // A calibration for a robot that is not there is a config error.
  c.calibration[0].number = 7;
  EXPECT_THROW(world::CameraSystem(w, c, world::BehindPolicy::Wait, nullptr), engine::ConfigError);
}

TEST(CameraSystem, JpegAndSpectatorImages) {
  world::World w(test::scenario(2));
  world::CameraSettings c = smallCameras();
  c.encoding = "jpeg";
  const auto images = oneCaptureWithSpectator(w, c);
  ASSERT_EQ(images.size(), 5u);  // 2 robots x 2 cameras + the spectator
  for (const auto& image : images) {
    if (image.camera == world::CameraId::Spectator) {
      EXPECT_EQ(image.encoding, world::ImageEncoding::Bgr);
      EXPECT_EQ(image.bgr.cols, 320);
      EXPECT_EQ(image.bgr.rows, 180);
      continue;
    }
    EXPECT_EQ(image.encoding, world::ImageEncoding::Jpeg);
    const cv::Mat decoded = cv::imdecode(image.data, cv::IMREAD_COLOR);
    ASSERT_FALSE(decoded.empty());
    EXPECT_EQ(decoded.cols, image.view.width);
    EXPECT_EQ(decoded.rows, image.view.height);
  }
}

TEST(CameraSystem, YuyvImagesAreTheRgbRenderingsConversionAndTheSpectatorStaysRgb) {
  // Robot cameras delivering YUYV are drawn in YUV and only packed; the
  // spectator in the same capture is drawn in RGB. Each image is what the
  // RGB rendering of its view gives through the CPU conversion (the
  // rasterisation of a view alone differs at a few edge pixels from the
  // same view in a batch; colours differ by the rounding only).
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  world::World w(test::scenario(2));
  world::CameraSettings c = smallCameras();
  c.top = {true, 160, 120, 30.0};
  const auto images = oneCaptureWithSpectator(w, c);
  ASSERT_EQ(images.size(), 5u);
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  engine::OffscreenRenderer renderer;
  for (const auto& image : images) {
    engine::RenderView view = image.view;
    view.format = engine::PixelFormat::Rgb;
    std::vector<cv::Mat> rgb;
    const engine::RenderView one[1] = {view};
    renderer.render(scene, one, rgb);
    cv::Mat expected, got_bytes;
    if (image.camera == world::CameraId::Spectator) {
      ASSERT_EQ(image.encoding, world::ImageEncoding::Bgr);
      cv::cvtColor(rgb[0], expected, cv::COLOR_RGB2BGR);
      got_bytes = image.bgr;
    } else {
      ASSERT_EQ(image.encoding, world::ImageEncoding::Yuyv);
      expected = engine::rgbToYuyv(rgb[0]);
      got_bytes =
          cv::Mat(view.height, view.width, CV_8UC2, const_cast<uint8_t*>(image.data.data()));
    }
    cv::Mat diff;
    cv::absdiff(expected, got_bytes, diff);
    const int beyond_rounding = cv::countNonZero(diff.reshape(1) > 2);
    const bool spectator = image.camera == world::CameraId::Spectator;
    std::printf("%s view (robot %d): %d of %zu bytes more than 2 levels apart\n",
                spectator ? "spectator" : "camera", static_cast<int>(image.robot), beyond_rounding,
                diff.total() * diff.channels());
    EXPECT_LE(beyond_rounding, static_cast<int>(diff.total() * diff.channels() / 500));
    if (spectator) {
      EXPECT_EQ(beyond_rounding, 0);  // RGB both ways: the same pixels
    }
  }
}

TEST(CameraSystem, ScenarioCamerasBlockIsReadAndChecked) {
  const test::TempDir dir("camera_cfg");
  auto write = [&](const std::string& cameras) {
    const auto file = dir / "s.yaml";
    std::ofstream(file) << "scenario: s\nfield: " << test::splField().string()
                        << "\nrobot_model: " << test::naoH25().string()
                        << "\nphysics: {dt: 0.005, control_period: 0.01}\nseed: 1\n"
                        << cameras;
    return file;
  };
  // The shipped example: every key, cameras on.
  const world::Scenario example =
      world::loadScenario(test::sourceDir() / "configs" / "scenarios" / "cameras_2v2.yaml");
  EXPECT_TRUE(example.cameras.enabled);
  EXPECT_EQ(example.cameras.calibration.size(), 1u);
  EXPECT_TRUE(example.cameras.spectator.enabled);
  const world::Scenario off = world::loadScenario(write(""));
  EXPECT_FALSE(off.cameras.enabled);  // off unless a scenario turns them on
  const world::Scenario on = world::loadScenario(
      write("cameras:\n  top: {width: 320, height: 240, rate: 15}\n  encoding: jpeg\n"
            "  effects: {noise: 2}\n  spectator: {position: [0, -7, 5]}\n"));
  EXPECT_TRUE(on.cameras.enabled);
  EXPECT_EQ(on.cameras.top.width, 320);
  EXPECT_EQ(on.cameras.top.rate, 15.0);
  EXPECT_EQ(on.cameras.bottom.width, 320);  // the default bottom camera
  EXPECT_EQ(on.cameras.encoding, "jpeg");
  EXPECT_TRUE(on.cameras.spectator.enabled);
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"cameras:\n  top: {width: 641}\n", "cameras.top.width"},
           {"cameras:\n  top: {rate: 200}\n", "cameras.top.rate"},
           {"cameras:\n  encoding: png\n", "cameras.encoding"},
           {"cameras:\n  effects: {noise: -1}\n", "cameras.effects.noise"},
           {"cameras:\n  lens: fisheye\n", "cameras.lens"},
           {"cameras:\n  calibration: [{team: 0, number: 1, camera: side, rpy: [0, 0, 0]}]\n",
            "camera"},
       }) {
    try {
      world::loadScenario(write(text));
      ADD_FAILURE() << "accepted: " << text;
    } catch (const engine::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("s.yaml"), std::string::npos) << e.what();
    }
  }
}

// A robot with one camera (a Booster K1's head camera): its images come from
// the `top` settings with the model's field of view, and it has no second view.
TEST(CameraSystem, ARobotWithOneCameraGetsOneView) {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  world::Scenario s = test::scenario(2);
  s.robots[1].model_file = test::boosterK1().string();
  world::World w(s);
  const robots::RobotModel& k1 = *w.robot(1).model;
  ASSERT_EQ(k1.cameraCount(), 1u);
  Collected got;
  world::CameraSystem cameras(w, smallCameras(), world::BehindPolicy::Wait, got.sink());
  cameras.capture(w);  // tick 0: both rates due
  cameras.flush();
  int nao = 0, booster = 0;
  for (const auto& image : got.images) {
    if (image.robot == 0) {
      ++nao;
      continue;
    }
    ++booster;
    EXPECT_EQ(image.camera, world::CameraId::Top);
    const engine::RenderView expected = world::robotCameraView(w, 1, k1.camera(0), 64, 48);
    EXPECT_TRUE(image.view.pose.isApprox(expected.pose, 1e-12));
    // The K1 camera's 105.6 deg: fx = 32 / tan(52.8 deg).
    EXPECT_NEAR(image.view.fx, 32.0 / std::tan(0.5 * k1.camera(0).horizontal_fov), 1e-9);
    EXPECT_NEAR(k1.camera(0).horizontal_fov, 1.8433, 1e-4);
  }
  EXPECT_EQ(nao, 2);
  EXPECT_EQ(booster, 1);
}

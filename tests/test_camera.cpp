// Off-screen cameras on real EGL (Mesa's llvmpipe here, no display): the
// pinhole geometry, colours, head motion, determinism, YUYV, and PNGs a
// person can look at.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "simsoccer/world/render_scene.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Vec3;

namespace {

engine::OffscreenRenderer& renderer() {
  // Rendering must not need a display: none is set for this process.
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  static engine::OffscreenRenderer r;
  return r;
}

// One Nao at (-2, 1.5) facing +x; the ball where the test puts it.
world::Scenario oneRobot() {
  world::Scenario s = test::scenario(1);
  s.robots[0].x = -2.0;
  s.robots[0].y = 1.5;
  s.ball_position = {-1.0, 1.5, -1.0};
  return s;
}

cv::Mat renderOne(world::World& w, const engine::RenderView& view, bool with_ball = true) {
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  if (!with_ball) std::erase_if(scene, [](const engine::DrawItem& d) { return d.ball_pattern; });
  std::vector<cv::Mat> images;
  const engine::RenderView views[1] = {view};
  renderer().render(scene, views, images);
  return images[0];
}

// The ball's blob: pixels that change when the ball is left out.
struct Blob {
  double u = 0, v = 0, width = 0;
  int pixels = 0;
};
Blob ballBlob(world::World& w, const engine::RenderView& view) {
  cv::Mat with = renderOne(w, view, true), without = renderOne(w, view, false), diff, mask;
  cv::absdiff(with, without, diff);
  cv::cvtColor(diff, mask, cv::COLOR_RGB2GRAY);
  mask = mask > 0;
  Blob b;
  const cv::Moments m = cv::moments(mask, true);
  b.pixels = cv::countNonZero(mask);
  if (m.m00 > 0) {
    b.u = m.m10 / m.m00 + 0.5;  // pixel centres are at i + 0.5
    b.v = m.m01 / m.m00 + 0.5;
    const cv::Rect r = cv::boundingRect(mask);
    b.width = r.width;
  }
  return b;
}

// Every robot's top (640x480) and bottom (320x240) view, robot by robot.
std::vector<engine::RenderView> bothCamerasOfEveryRobot(const world::World& w) {
  std::vector<engine::RenderView> views;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    views.push_back(world::robotCameraView(w, r, "CameraTop", 640, 480));
    views.push_back(world::robotCameraView(w, r, "CameraBottom", 320, 240));
  }
  return views;
}

bool isGreen(const cv::Vec3b& p) {
  return p[1] > p[0] + 40 && p[1] > p[2] + 40;
}

}  // namespace

TEST(Camera, RendersWithoutADisplay) {
  EXPECT_EQ(std::getenv("DISPLAY"), nullptr);
  const std::string name = renderer().glRenderer();
  std::printf("OpenGL renderer: %s\n", name.c_str());
  EXPECT_FALSE(name.empty());
}

TEST(Camera, BallAppearsWherePinholeModelPredicts) {
  world::World w(oneRobot());
  for (const auto& [camera, x, y] :
       {std::tuple{"CameraTop", -0.2, 1.5}, std::tuple{"CameraTop", 0.3, 1.9},
        std::tuple{"CameraTop", -0.5, 1.2}, std::tuple{"CameraBottom", -1.55, 1.5},
        std::tuple{"CameraBottom", -1.6, 1.62}}) {
    test::putBallOnCarpet(w, x, y);
    const bool top = std::string(camera) == "CameraTop";
    const engine::RenderView view =
        world::robotCameraView(w, 0, camera, top ? 640 : 320, top ? 480 : 240);
    const Vec3 centre = w.ballState().pose.translation();
    double u = 0, v = 0;
    ASSERT_TRUE(engine::projectPoint(view, centre, u, v));
    const double depth = (view.pose.inverse() * centre).x();
    const double predicted_width = 2.0 * view.fx * w.field().ball.radius / depth;
    const Blob b = ballBlob(w, view);
    std::printf(
        "%s ball at (%.2f, %.2f): predicted (%.1f, %.1f) width %.1f, seen (%.1f, %.1f) width "
        "%.0f\n",
        camera, x, y, u, v, predicted_width, b.u, b.v, b.width);
    ASSERT_GT(b.pixels, 10);
    EXPECT_NEAR(b.u, u, 2.0);
    EXPECT_NEAR(b.v, v, 2.0);
    EXPECT_NEAR(b.width, predicted_width, 0.1 * predicted_width + 1.0);
  }
}

TEST(Camera, CarpetLinesAndJerseyColours) {
  world::World w(oneRobot());
  // Looking ahead: the bottom rows of the top camera see carpet.
  const cv::Mat top = renderOne(w, world::robotCameraView(w, 0, "CameraTop", 640, 480));
  EXPECT_TRUE(isGreen(top.at<cv::Vec3b>(470, 320))) << top.at<cv::Vec3b>(470, 320);
  // Straight down from 2 m onto the centre line (x = 0): white in the middle,
  // green 0.3 m beside it.
  engine::Pose down = engine::Pose::Identity();
  down.translation() = Vec3(0.0, 2.0, 2.0);
  down.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();  // x -> -z
  const engine::RenderView above = engine::pinholeView(down, 200, 200, 0.5, 0.5);
  double u = 0, v = 0;
  ASSERT_TRUE(engine::projectPoint(above, Vec3(0.0, 2.0, 0.0), u, v));
  const cv::Mat img = renderOne(w, above);
  const cv::Vec3b line = img.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u));
  EXPECT_GT(line[0], 200);
  EXPECT_GT(line[1], 200);
  EXPECT_GT(line[2], 200);
  ASSERT_TRUE(engine::projectPoint(above, Vec3(0.3, 2.0, 0.0), u, v));
  EXPECT_TRUE(isGreen(img.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u))));
  // The torso from 1 m in front: team 0's blue jersey.
  const engine::Pose torso = w.torsoPose(0);
  engine::Pose front = engine::Pose::Identity();
  front.translation() = torso * Vec3(1.0, 0.0, 0.0);
  front.linear() = torso.linear() * Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  const cv::Mat body = renderOne(w, engine::pinholeView(front, 160, 120, 0.6, 0.45));
  const cv::Vec3b jersey = body.at<cv::Vec3b>(60, 80);
  EXPECT_GT(jersey[2], jersey[0] + 60) << jersey;  // blue over red
}

TEST(Camera, TurningTheHeadShiftsTheImageAsPredicted) {
  world::World w(oneRobot());
  test::putBallOnCarpet(w, -0.5, 2.0);  // 18 degrees to the robot's left
  const Blob before = ballBlob(w, world::robotCameraView(w, 0, "CameraTop", 640, 480));
  const int head_yaw = w.robot(0).model->body->jointIndex("HeadYaw");
  w.setJointTarget(0, head_yaw, 0.5, 1.0);  // look 0.5 rad to the left
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  const engine::RenderView turned = world::robotCameraView(w, 0, "CameraTop", 640, 480);
  double u = 0, v = 0;
  ASSERT_TRUE(engine::projectPoint(turned, w.ballState().pose.translation(), u, v));
  const Blob after = ballBlob(w, turned);
  std::printf("head yaw %.3f rad: ball u %.1f -> %.1f (predicted %.1f)\n",
              w.jointPosition(0, head_yaw), before.u, after.u, u);
  EXPECT_NEAR(w.jointPosition(0, head_yaw), 0.5, 0.02);
  EXPECT_GT(after.u - before.u, 250.0);  // the ball moves right in the image
  EXPECT_NEAR(after.u, u, 2.0);
  EXPECT_NEAR(after.v, v, 2.0);
}

TEST(Camera, SameStateSameBytesAndOneBatchForAllViews) {
  world::World w(test::scenario(4));
  const std::vector<engine::RenderView> views = bothCamerasOfEveryRobot(w);
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  std::vector<cv::Mat> a, b;
  renderer().render(scene, views, a);
  const auto t = renderer().lastTiming();
  std::printf(
      "8 views in one %dx%d framebuffer: draw %.1f ms, readback %.1f ms, %zu triangles per view\n",
      t.atlas_width, t.atlas_height, t.draw_ms, t.readback_ms, t.triangles_per_view);
  renderer().render(scene, views, b);
  ASSERT_EQ(a.size(), 8u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].size(), b[i].size());
    EXPECT_EQ(cv::norm(a[i], b[i], cv::NORM_INF), 0.0) << "view " << i;
  }
  EXPECT_EQ(a[1].cols, 320);
  EXPECT_EQ(a[1].rows, 240);
  // Robot 0's top image differs from robot 2's (another place on the field).
  EXPECT_GT(cv::norm(a[0], a[4], cv::NORM_L1), 0.0);
}

TEST(Camera, AViewInABatchOf44RendersAsItDoesAlone) {
  // 22 robots' 44 views packed into one framebuffer: each comes out as when
  // it is drawn alone (no view bleeds into another, culling and level of
  // detail are per view) but for a few edge pixels rasterised at another
  // offset in the framebuffer, and the packing leaves little unused.
  world::World w(test::scenario(22));
  const std::vector<engine::RenderView> views = bothCamerasOfEveryRobot(w);
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  std::vector<cv::Mat> batch;
  renderer().render(scene, views, batch);
  const auto t = renderer().lastTiming();
  double used = 0;
  for (const auto& v : views) used += static_cast<double>(v.width) * v.height;
  const double fill = used / (static_cast<double>(t.atlas_width) * t.atlas_height);
  std::printf("44 views in %dx%d (%.0f %% used), %zu triangles per view, draw %.1f ms\n",
              t.atlas_width, t.atlas_height, 100 * fill, t.triangles_per_view, t.draw_ms);
  EXPECT_GT(fill, 0.9);
  for (size_t i : {size_t{0}, size_t{1}, size_t{20}, size_t{31}, size_t{43}}) {
    std::vector<cv::Mat> alone;
    const engine::RenderView one[1] = {views[i]};
    renderer().render(scene, one, alone);
    cv::Mat diff;
    cv::absdiff(alone[0], batch[i], diff);
    cv::cvtColor(diff, diff, cv::COLOR_RGB2GRAY);
    std::printf("view %zu: %d pixels differ\n", i, cv::countNonZero(diff));
    EXPECT_LE(cv::countNonZero(diff), static_cast<int>(diff.total() / 10000)) << "view " << i;
  }
  // And they show the scene: blank views would agree too. A bottom camera may
  // see only carpet; every top camera sees lines, goals or robots.
  for (size_t i = 0; i < views.size(); i += 2) {
    cv::Scalar mean, spread;
    cv::meanStdDev(batch[i], mean, spread);
    EXPECT_GT(spread[1], 5.0) << "top camera view " << i;
  }
}

TEST(Camera, CapsuleAndItsCoarseStandInWherePredicted) {
  // A capsule (radius 5 cm, 40 cm long) lying across the view at 2 m and at
  // 8 m, where it is drawn with three sides: its extent in the image is the
  // pinhole model's, within the polygons' deviation from a circle.
  engine::Pose eye = engine::Pose::Identity();
  eye.translation() = Vec3(0.0, 0.0, 0.5);
  const engine::RenderView view = engine::pinholeView(eye, 640, 480, 0.98, 0.76);
  for (double distance : {2.0, 8.0}) {
    engine::DrawItem capsule;
    capsule.shape = engine::Primitive::Capsule;
    capsule.stretch = (0.2f - 0.05f) / 0.05f;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.block<3, 3>(0, 0) =
        Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix() * 0.05;  // z -> -y
    m.block<3, 1>(0, 3) = Vec3(distance, 0.0, 0.5);
    capsule.transform = m.cast<float>();
    std::vector<cv::Mat> images;
    const engine::RenderView views[1] = {view};
    const engine::DrawItem scene[1] = {capsule};
    renderer().render(scene, views, images);
    cv::Mat grey, mask;
    cv::cvtColor(images[0], grey, cv::COLOR_RGB2GRAY);
    mask = grey > 120;  // a white capsule (lit at least 0.6) on the hall's grey (0.35)
    const cv::Rect box = cv::boundingRect(mask);
    const double length = 0.4 * view.fx / distance, thickness = 0.1 * view.fy / distance;
    std::printf("capsule at %.0f m: %d x %d px, predicted %.1f x %.1f\n", distance, box.width,
                box.height, length, thickness);
    EXPECT_NEAR(box.x + 0.5 * box.width, view.cx, 1.0);
    EXPECT_NEAR(box.y + 0.5 * box.height, view.cy, 1.0);
    // The caps' tips are exact; a bit nearer than the centre, so a little wider.
    EXPECT_NEAR(box.width, length, 0.05 * length + 1.0);
    EXPECT_NEAR(box.height, thickness, (distance < 5 ? 0.1 : 0.35) * thickness + 1.0);
  }
}

namespace {
// BT.601 full-range YCbCr in Y, Cb, Cr order (OpenCV's YCrCb has Y, Cr, Cb), as the Nao's
// camera delivers it.
cv::Mat ycbcr(const cv::Mat& rgb) {
  cv::Mat ycrcb, out(rgb.size(), CV_8UC3);
  cv::cvtColor(rgb, ycrcb, cv::COLOR_RGB2YCrCb);
  const int from_to[] = {0, 0, 1, 2, 2, 1};
  cv::mixChannels(&ycrcb, 1, &out, 1, from_to, 3);
  return out;
}
}  // namespace

TEST(Camera, YuyvIsTheCamerasYCbCrWithinRounding) {
  cv::Mat rgb(480, 640, CV_8UC3);
  cv::randu(rgb, cv::Scalar::all(0), cv::Scalar::all(256));
  // Every 8-bit value of each channel appears: the extremes are where rounding differs.
  for (int i = 0; i < 256; ++i) {
    rgb.at<cv::Vec3b>(0, i) = {static_cast<uint8_t>(i), 0, 255};
    rgb.at<cv::Vec3b>(1, i) = {255, static_cast<uint8_t>(i), 0};
    rgb.at<cv::Vec3b>(2, i) = {0, 255, static_cast<uint8_t>(i)};
  }
  const cv::Mat yuyv = engine::rgbToYuyv(rgb);
  const cv::Mat yuv = ycbcr(rgb);
  ASSERT_EQ(yuyv.type(), CV_8UC2);
  for (int r = 0; r < rgb.rows; ++r)
    for (int c = 0; c < rgb.cols; c += 2) {
      const uint8_t* q = yuyv.ptr<uint8_t>(r) + 2 * c;
      const cv::Vec3b a = yuv.at<cv::Vec3b>(r, c), b = yuv.at<cv::Vec3b>(r, c + 1);
      ASSERT_EQ(q[0], a[0]) << r << "," << c;
      ASSERT_EQ(q[2], b[0]) << r << "," << c;
      ASSERT_NEAR(q[1], 0.5 * (a[1] + b[1]), 0.5 + 1e-9) << r << "," << c;
      ASSERT_NEAR(q[3], 0.5 * (a[2] + b[2]), 0.5 + 1e-9) << r << "," << c;
    }
  // RGBA input (the renderer's) gives the same bytes.
  cv::Mat rgba;
  cv::cvtColor(rgb, rgba, cv::COLOR_RGB2RGBA);
  EXPECT_EQ(cv::norm(engine::rgbToYuyv(rgba), yuyv, cv::NORM_INF), 0.0);
  // And back as team code decodes it (B-Human's ColorModelConversions: R = Y + 1.402 (Cr - 128),
  // G = Y - 0.344 (Cb - 128) - 0.714 (Cr - 128), B = Y + 1.772 (Cb - 128)): a flat colour
  // survives (chroma shared by each pair).
  const cv::Vec3b colour(30, 140, 40);
  cv::Mat flat(4, 4, CV_8UC3, cv::Scalar(colour[0], colour[1], colour[2]));
  const cv::Mat packed = engine::rgbToYuyv(flat);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      const uint8_t* q = packed.ptr<uint8_t>(r) + 4 * (c / 2);
      const double y = q[c % 2 == 0 ? 0 : 2], cb = q[1] - 128.0, cr = q[3] - 128.0;
      EXPECT_NEAR(y + 1.402 * cr, colour[0], 2.0);
      EXPECT_NEAR(y - 0.344 * cb - 0.714 * cr, colour[1], 2.0);
      EXPECT_NEAR(y + 1.772 * cb, colour[2], 2.0);
    }
  EXPECT_THROW(engine::rgbToYuyv(cv::Mat(2, 3, CV_8UC3)), std::invalid_argument);
}

TEST(Camera, AYuvViewHoldsTheRgbViewsYuvWhicheverFormatTheOthersUse) {
  // A view drawn in YUV is the YCbCr of the same view drawn in RGB,
  // within the rounding of two 8-bit conversions, ball patches and the hall
  // behind the field included, whether the framebuffer was cleared for YUV
  // views (most of them) or for RGB ones.
  world::World w(test::scenario(4));
  test::putBallOnCarpet(w, -2.0, 0.3);
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  const engine::RenderView rgb = world::robotCameraView(w, 0, "CameraTop", 640, 480);
  engine::RenderView yuv = rgb;
  yuv.format = engine::PixelFormat::Yuv;
  const engine::RenderView other = world::robotCameraView(w, 2, "CameraTop", 640, 480);
  engine::RenderView other_yuv = other;
  other_yuv.format = engine::PixelFormat::Yuv;
  for (const auto& views :
       {std::vector{rgb, yuv}, std::vector{yuv, other_yuv, rgb}, std::vector{rgb, other, yuv}}) {
    std::vector<cv::Mat> images;
    renderer().render(scene, views, images);
    const size_t r =
        std::find_if(views.begin(), views.end(),
                     [](const auto& v) { return v.format == engine::PixelFormat::Rgb; }) -
        views.begin();
    const size_t y = &views.back() == &views[r] ? 0 : views.size() - 1;
    ASSERT_EQ(views[y].format, engine::PixelFormat::Yuv);
    cv::Mat diff;
    const cv::Mat expected = ycbcr(images[r]);
    cv::absdiff(expected, images[y], diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    std::printf("%zu views: YUV view %zu against view %zu converted: at most %.0f levels apart\n",
                views.size(), y, r, worst);
    EXPECT_LE(worst, 2.0);
    // Not a flat image: the carpet, lines, the ball and the hall are all there.
    cv::Scalar mean, spread;
    cv::meanStdDev(images[y], mean, spread);
    EXPECT_GT(spread[0], 10.0);
    // The hall behind the field (the clear colour) is in the compared view.
    cv::Mat hall;
    cv::inRange(images[r], cv::Scalar(89, 89, 97), cv::Scalar(89, 89, 97), hall);
    EXPECT_GT(cv::countNonZero(hall), 1000);
  }
}

TEST(Camera, YuvPacksAsYuyvAsTheRgbConversionDoes) {
  cv::Mat rgb(48, 66, CV_8UC3);  // a width that leaves pairs after the 32-pixel blocks
  cv::randu(rgb, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::Mat yuva, a, b;
  const cv::Mat yuv = ycbcr(rgb);
  cv::cvtColor(yuv, yuva, cv::COLOR_RGB2RGBA);  // a fourth channel of 255, as a Yuv view has
  const cv::Mat expected = engine::rgbToYuyv(rgb);
  engine::yuvToYuyv(yuv, a);
  engine::yuvToYuyv(yuva, b);
  ASSERT_EQ(a.type(), CV_8UC2);
  EXPECT_EQ(cv::norm(a, expected, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(b, expected, cv::NORM_INF), 0.0);
  EXPECT_THROW(engine::yuvToYuyv(cv::Mat(2, 3, CV_8UC4), a), std::invalid_argument);
  EXPECT_THROW(engine::yuvToYuyv(cv::Mat(2, 4, CV_8UC1), a), std::invalid_argument);
}

TEST(Camera, WritesTopCameraAndSpectatorPngs) {
  world::World w(test::scenario(10));
  test::putBallOnCarpet(w, -1.5, 0.3);
  std::vector<engine::RenderView> views = {world::robotCameraView(w, 0, "CameraTop", 640, 480)};
  engine::Pose side = engine::Pose::Identity();  // above the touchline, looking at the field
  side.translation() = Vec3(0.0, -5.5, 3.5);
  side.linear() =
      (Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()) * Eigen::AngleAxisd(0.55, Vec3::UnitY()))
          .toRotationMatrix();
  views.push_back(engine::pinholeView(side, 960, 540, 1.6, 1.0));
  std::vector<engine::DrawItem> scene;
  world::buildRenderScene(w, scene);
  std::vector<cv::Mat> images;
  renderer().render(scene, views, images);
  const auto dir = std::filesystem::current_path();
  for (const auto& [name, image] :
       {std::pair{"camera_top.png", images[0]}, std::pair{"spectator.png", images[1]}}) {
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_RGB2BGR);
    ASSERT_TRUE(cv::imwrite((dir / name).string(), bgr));
    const cv::Mat back = cv::imread((dir / name).string());
    EXPECT_EQ(back.size(), image.size());
    std::printf("wrote %s\n", (dir / name).c_str());
  }
  // The spectator sees carpet in the lower middle of its image, the hall above.
  EXPECT_TRUE(isGreen(images[1].at<cv::Vec3b>(420, 300)));
  EXPECT_TRUE(isGreen(images[1].at<cv::Vec3b>(400, 700)));
  EXPECT_FALSE(isGreen(images[1].at<cv::Vec3b>(20, 480)));
}

TEST(Camera, CentreLineSeenFromTheRobotWherePredicted) {
  // The robot at (-2, 1.5) faces +x: the centre line (x = 0, 50 mm wide) is 2 m ahead.
  world::World w(oneRobot());
  const engine::RenderView view = world::robotCameraView(w, 0, "CameraTop", 640, 480);
  const cv::Mat img = renderOne(w, view, false);
  // Along the image column of y = 1.5 (straight ahead), the white rows should
  // span the projections of the line's near and far edges (x = -0.025, +0.025).
  double u_near = 0, v_near = 0, u_far = 0, v_far = 0;
  ASSERT_TRUE(engine::projectPoint(view, Vec3(-0.025, 1.5, 0.0), u_near, v_near));
  ASSERT_TRUE(engine::projectPoint(view, Vec3(0.025, 1.5, 0.0), u_far, v_far));
  const int column = static_cast<int>(u_near);
  // (Within 20 rows of the prediction: farther up the column are the lines
  // of the far half.)
  int first = -1, last = -1;
  for (int row = static_cast<int>(v_far) - 20; row < static_cast<int>(v_near) + 20; ++row) {
    const cv::Vec3b p = img.at<cv::Vec3b>(row, column);
    if (p[0] > 200 && p[1] > 200 && p[2] > 200) {
      if (first < 0) first = row;
      last = row;
    }
  }
  std::printf("centre line 2 m ahead: predicted rows %.1f..%.1f, white rows %d..%d\n", v_far,
              v_near, first, last);
  ASSERT_GE(first, 0) << "no white line in column " << column;
  for (int row = first; row <= last; ++row)  // one unbroken band
    EXPECT_TRUE(img.at<cv::Vec3b>(row, column)[1] > 200) << "row " << row;
  EXPECT_NEAR(first, v_far, 1.5);
  EXPECT_NEAR(last + 1, v_near, 1.5);
}

TEST(Camera, BottomCameraLooksDownAtTheFeet) {
  world::World w(oneRobot());
  const int head_pitch = w.robot(0).model->body->jointIndex("HeadPitch");
  w.setJointTarget(0, head_pitch, 0.5, 1.0);  // head down, as when dribbling
  for (int i = 0; i < 100; ++i) w.stepControlPeriod();
  const engine::RenderView view = world::robotCameraView(w, 0, "CameraBottom", 320, 240);
  const cv::Mat img = renderOne(w, view);
  for (const char* foot : {"LFoot", "RFoot"}) {
    const int link = w.robot(0).model->body->linkIndex(foot);
    // The toe cap: 9 cm ahead of the ankle, 3 cm above the sole.
    const Vec3 toe = w.linkPose(0, link) * Vec3(0.09, 0.0, -0.015);
    double u = 0, v = 0;
    ASSERT_TRUE(engine::projectPoint(view, toe, u, v));
    std::printf("%s toe at (%.1f, %.1f) in the bottom image\n", foot, u, v);
    ASSERT_GE(u, 0);
    ASSERT_LT(u, 320);
    ASSERT_GE(v, 0);
    ASSERT_LT(v, 240);
    const cv::Vec3b p = img.at<cv::Vec3b>(static_cast<int>(v), static_cast<int>(u));
    EXPECT_FALSE(isGreen(p)) << foot << " " << p;  // the robot's own body, not carpet
  }
  cv::Mat bgr;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
  cv::imwrite((std::filesystem::current_path() / "camera_bottom_feet.png").string(), bgr);
}

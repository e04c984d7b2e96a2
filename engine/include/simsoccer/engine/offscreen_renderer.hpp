// Off-screen OpenGL rendering through EGL without a display (Mesa's
// llvmpipe on CPU machines, a GPU's EGL driver where there is one): many
// camera views of one instanced scene drawn into one framebuffer per frame,
// read back once.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::engine {

class RenderError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Unit meshes: box -0.5..0.5 on each axis (12 triangles); sphere of radius 1
// (192 triangles, for the ball); a coarse sphere (an icosahedron, 20
// triangles, for robot parts); cylinder of radius 1 and length 1 along z,
// centred (24 triangles); a quad -0.5..0.5 in x and y facing +z (2 triangles,
// for paint on the ground); a capsule of radius 1 along z whose end caps are
// centred at z = +-DrawItem::stretch (a hexagonal prism with hexagonal pyramid
// ends, 24 triangles: one instance where a cylinder and two spheres took 64,
// and llvmpipe pays per triangle).
enum class Primitive : uint8_t { Box, Sphere, CoarseSphere, Cylinder, Quad, Capsule };

// One instance of a unit mesh in the world frame.
struct DrawItem {
  Primitive shape = Primitive::Box;
  Eigen::Matrix4f transform = Eigen::Matrix4f::Identity();  // world from unit mesh (with scale)
  Eigen::Vector3f colour = Eigen::Vector3f::Ones();         // linear RGB, 0..1
  bool ball_pattern = false;                                // black patches on white (the SPL ball)
  // Paint on the ground (carpet, floor, lines: flat, nothing lies under it):
  // drawn before everything else, in the scene's order, without the depth
  // test, later paint over earlier. It covers most of every robot camera's
  // image, and without depth reads and writes llvmpipe shades it about 5
  // times faster. Only Quad.
  bool ground = false;
  float stretch = 0.0f;  // Capsule: half the distance between the cap centres, in radii
};

// The colour space a view is drawn in. Rgb: the scene's colours, as R, G, B,
// 255 in the four 8-bit channels. Yuv: their BT.601 full-range YCbCr, as the Nao's camera
// delivers it (Y, Cb, Cr, 255; OpenCV's RGB -> YCrCb with the chroma in that order),
// computed with the lighting per vertex: a camera that delivers YUV
// 4:2:2 then only packs pixel pairs (yuvToYuyv) instead of converting every
// pixel on the CPU, and the rasteriser's cost per pixel stays the same.
enum class PixelFormat : uint8_t { Rgb, Yuv };

// A pinhole camera. `pose` is the camera frame in the world: x forward
// (optical axis), y left, z up. Pixel (u, v): u right, v down, pixel i
// covering [i, i + 1); a point at depth d projects to u = cx + fx * (-y / d).
struct RenderView {
  Pose pose = Pose::Identity();
  int width = 640, height = 480;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // px
  double near_clip = 0.01, far_clip = 60.0;       // m
  PixelFormat format = PixelFormat::Rgb;
};

// Intrinsics from the fields of view (rad), centred principal point.
RenderView pinholeView(const Pose& pose, int width, int height, double horizontal_fov,
                       double vertical_fov);
// Where a world point lands in a view (u right, v down, px); false if behind.
bool projectPoint(const RenderView& view, const Vec3& world_point, double& u, double& v);
// The same for a point already in the camera frame (`pose`'s inverse applied): a caller
// projecting many points into one view inverts its pose once.
bool projectCameraPoint(const RenderView& view, const Vec3& camera_point, double& u, double& v);

struct RenderTiming {
  double draw_ms = 0.0, readback_ms = 0.0;
  int atlas_width = 0, atlas_height = 0;
  size_t triangles = 0;           // drawn in all views together, after culling
  size_t triangles_per_view = 0;  // their mean per view
};

class OffscreenRenderer {
 public:
  // Opens EGL on the surfaceless Mesa platform (or the first EGL device),
  // creates an OpenGL 3.3 core context; throws RenderError saying which step failed.
  OffscreenRenderer();
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  std::string glRenderer() const;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

  // Draws the scene in every view into one framebuffer (one viewport each;
  // instances outside a view's frustum are culled) and reads it back once.
  // Must be called on the thread that created the renderer.
  void render(std::span<const DrawItem> scene, std::span<const RenderView> views);
  // View i of the last render as 8-bit RGBA (CV_8UC4, R first, top row
  // first; Y, Cb, Cr, 255 for a Yuv view): a region of the readback. Two readback buffers
  // alternate, so the pixels stay valid until the second render after this one: one frame's images
  // can be converted on another thread while the next is drawn.
  cv::Mat image(size_t view) const;
  // The same, with `images[i]` a three-channel copy (CV_8UC3: RGB, or YUV) of view i.
  void render(std::span<const DrawItem> scene, std::span<const RenderView> views,
              std::vector<cv::Mat>& images);
  const RenderTiming& lastTiming() const { return timing_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  RenderTiming timing_;
};

// The Nao's image format: YCbCr 4:2:2 as Y0 Cb Y1 Cr (YUYV), from 8-bit RGB or RGBA,
// BT.601 full range (OpenCV's RGB -> YCrCb); each pixel pair shares the mean of
// its two chroma values. `width` must be even.
cv::Mat rgbToYuyv(const cv::Mat& rgb);
// The same into `out` (written in place when it already is rows x cols CV_8UC2).
void rgbToYuyv(const cv::Mat& rgb, cv::Mat& out);
// YUYV from 8-bit YUV or YUVA (a Yuv view): the same packing, no colour conversion.
void yuvToYuyv(const cv::Mat& yuv, cv::Mat& out);

}  // namespace simsoccer::engine

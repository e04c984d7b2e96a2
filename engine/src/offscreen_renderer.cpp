#include "simsoccer/engine/offscreen_renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

namespace simsoccer::engine {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Lighting per vertex (Lambert under a fixed sky light), so the fragment
// stage, which llvmpipe runs for every one of millions of pixels per frame,
// only writes a colour.
const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in mat4 model;   // locations 2..5
layout(location = 6) in vec3 colour;
layout(location = 7) in float stretch;  // capsules: caps moved apart along z
uniform mat4 view_projection;
uniform mat3 colour_transform;  // the view's PixelFormat: identity, or RGB -> YUV
uniform vec3 colour_offset;
flat out vec3 lit_colour;
flat out vec3 patch_colour;  // the ball's black patches in the view's colour space
out vec3 object_position;
void main() {
  vec3 p = position + vec3(0.0, 0.0, sign(position.z) * stretch);
  gl_Position = view_projection * model * vec4(p, 1.0);
  vec3 n = normalize(mat3(model) * normal);
  vec3 lit = colour * (0.6 + 0.4 * max(dot(n, normalize(vec3(0.3, 0.2, 1.0))), 0.0));
  lit_colour = colour_transform * lit + colour_offset;
  patch_colour = colour_transform * vec3(0.05) + colour_offset;
  object_position = position;
}
)";

const char* kPlainFragmentShader = R"(#version 330 core
flat in vec3 lit_colour;
out vec4 fragment;
void main() { fragment = vec4(lit_colour, 1.0); }
)";

// The ball's black patches: the 12 directions of an icosahedron's vertices
// (a pentagon pattern's centres). Only the ball's pixels run this.
const char* kPatternFragmentShader = R"(#version 330 core
flat in vec3 lit_colour;
flat in vec3 patch_colour;
in vec3 object_position;
out vec4 fragment;
void main() {
  const float g = 1.618034;
  vec3 a = abs(normalize(object_position));
  float best = max(max(dot(a, normalize(vec3(0.0, 1.0, g))), dot(a, normalize(vec3(1.0, g, 0.0)))),
                   dot(a, normalize(vec3(g, 0.0, 1.0))));
  fragment = vec4(best > 0.93 ? patch_colour : lit_colour, 1.0);
}
)";

struct Mesh {
  GLuint vao = 0, vertices = 0, indices = 0;
  GLsizei index_count = 0;
};

struct Vertex {
  float p[3];
  float n[3];
};

struct Instance {
  float model[16];  // column-major
  float colour[3];
  float stretch;
};

// Draw batches: the ground paint first (painter's order, no depth test), then
// one per unit mesh with the depth test, the ball's patterned sphere apart
// (its own fragment program).
// Meshes: one per Primitive, then the coarse stand-ins drawn for small
// instances (level of detail): an octahedron for the coarse sphere (8
// triangles) and a capsule with three sides (12).
constexpr size_t kOctahedronMesh = 6, kThinCapsuleMesh = 7, kMeshCount = 8;
constexpr size_t meshOf(Primitive p) {
  return static_cast<size_t>(p);
}
enum Batch : size_t {
  kGroundBatch,  // drawn first, without the depth test
  kCoarseSphereBatch,
  kOctahedronBatch,
  kCapsuleBatch,
  kThinCapsuleBatch,
  kCylinderBatch,
  kSphereBatch,
  kPatternBatch,  // the ball: the sphere with the pattern program
  kBoxBatch,
  kQuadBatch,
  kBatchCount
};
constexpr std::array<size_t, kBatchCount> kBatchMesh{
    meshOf(Primitive::Quad),   meshOf(Primitive::CoarseSphere),
    kOctahedronMesh,           meshOf(Primitive::Capsule),
    kThinCapsuleMesh,          meshOf(Primitive::Cylinder),
    meshOf(Primitive::Sphere), meshOf(Primitive::Sphere),
    meshOf(Primitive::Box),    meshOf(Primitive::Quad)};
// A sphere or capsule whose radius spans fewer pixels than this in a view is
// drawn there with its coarse stand-in: the octahedron's outline strays 0.16
// radii further from the circle than the icosahedron's, the three-sided
// capsule's 0.3 radii further than the six-sided one's, under 2 px at these
// sizes; robots a few metres away are mostly such parts.
constexpr float kCoarseSpherePixels = 10.0f, kThinCapsulePixels = 6.0f;

// The batch of the coarse stand-in for an instance of `radius_px` pixels
// (its radius times the focal length over its distance), or `batch` itself.
constexpr size_t levelOfDetail(size_t batch, float radius_px) {
  if (batch == kCoarseSphereBatch && radius_px < kCoarseSpherePixels) return kOctahedronBatch;
  if (batch == kCapsuleBatch && radius_px < kThinCapsulePixels) return kThinCapsuleBatch;
  return batch;
}

constexpr float kIcosahedronScale = 2.0f / (1.0f + 0.7946545f);

// A view's colours from the scene's linear RGB (0..1): out = transform * rgb
// + offset. Yuv is BT.601 full-range YCbCr, as the Nao's camera delivers it and team code
// decodes it (B-Human: R = Y + 1.402 (Cr - 128), B = Y + 1.772 (Cb - 128)): BT.601 luma,
// Cb = 0.564 (B - Y) and Cr = 0.713 (R - Y), both offset by 128 of 255 (OpenCV's YCrCb, in
// Y, Cb, Cr order), so that a Yuv view holds what rgbToYuyv would compute from the Rgb view,
// up to rounding. (Until 2026-12-07 it was OpenCV's analogue YUV, U = 0.492 (B - Y), V =
// 0.877 (R - Y): chroma 0.87 and 1.23 times a camera's.)
struct ColourTransform {
  Eigen::Matrix3f transform = Eigen::Matrix3f::Identity();
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
  Eigen::Vector3f operator()(const Eigen::Vector3f& rgb) const { return transform * rgb + offset; }
};

ColourTransform colourTransform(PixelFormat format) {
  ColourTransform t;
  if (format == PixelFormat::Rgb) return t;
  const Eigen::RowVector3f y(0.299f, 0.587f, 0.114f);
  t.transform.row(0) = y;
  t.transform.row(1) = 0.564f * (Eigen::RowVector3f(0, 0, 1) - y);
  t.transform.row(2) = 0.713f * (Eigen::RowVector3f(1, 0, 0) - y);
  t.offset = Eigen::Vector3f(0.0f, 128.0f / 255.0f, 128.0f / 255.0f);
  return t;
}

size_t batchOf(const DrawItem& d) {
  if (d.ground) return kGroundBatch;
  if (d.ball_pattern) return kPatternBatch;
  switch (d.shape) {
    case Primitive::CoarseSphere:
      return kCoarseSphereBatch;
    case Primitive::Capsule:
      return kCapsuleBatch;
    case Primitive::Cylinder:
      return kCylinderBatch;
    case Primitive::Sphere:
      return kSphereBatch;
    case Primitive::Box:
      return kBoxBatch;
    case Primitive::Quad:
      return kQuadBatch;
  }
  return kBoxBatch;
}

// Radius of the unit mesh's bounding sphere (box corners at sqrt(3)/2; the
// cylinder's rim at sqrt(1 + 0.25); a capsule's tips at 1 + stretch).
float unitRadius(Primitive p, float stretch) {
  switch (p) {
    case Primitive::Capsule:
      return 1.0f + stretch;
    case Primitive::Box:
      return 0.8661f;
    case Primitive::Cylinder:
      return 1.1181f;
    case Primitive::Quad:
      return 0.7072f;
    case Primitive::CoarseSphere:
      return kIcosahedronScale;
    default:
      return 1.0f;
  }
}

void unitBox(std::vector<Vertex>& v, std::vector<uint32_t>& idx) {
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      const auto base = static_cast<uint32_t>(v.size());
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      for (int k = 0; k < 4; ++k) {
        Vertex x{};
        x.p[axis] = 0.5f * static_cast<float>(sign);
        x.p[a1] = (k == 1 || k == 2) ? 0.5f : -0.5f;
        x.p[a2] = (k >= 2) ? 0.5f : -0.5f;
        x.n[axis] = static_cast<float>(sign);
        v.push_back(x);
      }
      idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
}

// An icosahedron standing in for the unit sphere, one normal per face (flat shading).
void unitIcosahedron(std::vector<Vertex>& v, std::vector<uint32_t>& idx) {
  const float g = 1.618034f;
  std::array<Eigen::Vector3f, 12> p{
      Eigen::Vector3f(-1, g, 0),  Eigen::Vector3f(1, g, 0),   Eigen::Vector3f(-1, -g, 0),
      Eigen::Vector3f(1, -g, 0),  Eigen::Vector3f(0, -1, g),  Eigen::Vector3f(0, 1, g),
      Eigen::Vector3f(0, -1, -g), Eigen::Vector3f(0, 1, -g),  Eigen::Vector3f(g, 0, -1),
      Eigen::Vector3f(g, 0, 1),   Eigen::Vector3f(-g, 0, -1), Eigen::Vector3f(-g, 0, 1)};
  for (auto& x : p) x.normalize();
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  // Scaled so that the unit sphere lies midway between the faces' centres
  // (inradius 0.7947 of a unit icosahedron) and the vertices.
  const float scale = kIcosahedronScale;
  for (const auto& f : faces) {
    Eigen::Vector3f n = (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]).normalized();
    std::array<int, 3> order{f[0], f[1], f[2]};
    if (n.dot(p[f[0]]) < 0) {  // outward, counter-clockwise
      std::swap(order[1], order[2]);
      n = -n;
    }
    for (int k : order) {
      const Eigen::Vector3f x = p[k] * scale;
      idx.push_back(static_cast<uint32_t>(v.size()));
      v.push_back({{x.x(), x.y(), x.z()}, {n.x(), n.y(), n.z()}});
    }
  }
}

// Appends a triangle with its own three vertices and one normal (flat shading).
void addFace(std::vector<Vertex>& v, std::vector<uint32_t>& idx, const Eigen::Vector3f& a,
             const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& n) {
  for (const Eigen::Vector3f* x : {&a, &b, &c}) {
    idx.push_back(static_cast<uint32_t>(v.size()));
    v.push_back({{x->x(), x->y(), x->z()}, {n.x(), n.y(), n.z()}});
  }
}

// An octahedron standing in for the unit sphere at a distance, scaled like
// the icosahedron (the sphere midway between its faces, inradius 1/sqrt(3)
// unscaled, and its vertices).
void unitOctahedron(std::vector<Vertex>& v, std::vector<uint32_t>& idx) {
  const float s = 2.0f / (1.0f + 1.0f / std::sqrt(3.0f));
  for (int octant = 0; octant < 8; ++octant) {
    const float sx = octant & 1 ? -1.0f : 1.0f, sy = octant & 2 ? -1.0f : 1.0f,
                sz = octant & 4 ? -1.0f : 1.0f;
    const Eigen::Vector3f a(sx * s, 0, 0), b(0, sy * s, 0), c(0, 0, sz * s);
    const Eigen::Vector3f n = Eigen::Vector3f(sx, sy, sz).normalized();
    if (sx * sy * sz > 0)  // counter-clockwise seen from outside
      addFace(v, idx, a, b, c, n);
    else
      addFace(v, idx, a, c, b, n);
  }
}

// A capsule of radius 1: a prism with `slices` sides from z = -0 to +0 (the
// vertex shader moves each half out by the instance's stretch) capped by
// pyramids with their tips at z = +-1, one normal per face; the polygon
// scaled so that the unit circle lies midway between its sides and corners.
// The prism's rims sit at z = +-1e-6 so that the shader's sign(z) knows their side.
void unitCapsule(std::vector<Vertex>& v, std::vector<uint32_t>& idx, int slices) {
  const float rim = 1e-6f;
  const double scale = 2.0 / (1.0 + std::cos(M_PI / slices));
  const auto corner = [&](int j) {
    const double ph = 2 * M_PI * j / slices;
    return Eigen::Vector3f(static_cast<float>(scale * std::cos(ph)),
                           static_cast<float>(scale * std::sin(ph)), 0);
  };
  for (int j = 0; j < slices; ++j) {
    const Eigen::Vector3f a = corner(j), b = corner(j + 1);
    const Eigen::Vector3f side = (a + b).normalized();
    const Eigen::Vector3f up(0, 0, rim), down(0, 0, -rim);
    // Side: counter-clockwise seen from outside.
    addFace(v, idx, a + down, b + down, b + up, side);
    addFace(v, idx, a + down, b + up, a + up, side);
    for (float end : {1.0f, -1.0f}) {
      const Eigen::Vector3f tip(0, 0, end), base_a = a + end * up, base_b = b + end * up;
      const Eigen::Vector3f n = ((base_b - base_a).cross(tip - base_a) * end).normalized();
      if (end > 0)
        addFace(v, idx, base_a, base_b, tip, n);
      else
        addFace(v, idx, base_b, base_a, tip, n);
    }
  }
}

void unitQuad(std::vector<Vertex>& v, std::vector<uint32_t>& idx) {
  v = {{{-0.5f, -0.5f, 0}, {0, 0, 1}},
       {{0.5f, -0.5f, 0}, {0, 0, 1}},
       {{0.5f, 0.5f, 0}, {0, 0, 1}},
       {{-0.5f, 0.5f, 0}, {0, 0, 1}}};
  idx = {0, 1, 2, 0, 2, 3};
}

// Low tessellation on purpose: llvmpipe's cost grows with triangles.
void unitSphere(std::vector<Vertex>& v, std::vector<uint32_t>& idx, int slices, int stacks) {
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      const float x = static_cast<float>(std::sin(th) * std::cos(ph));
      const float y = static_cast<float>(std::sin(th) * std::sin(ph));
      const float z = static_cast<float>(std::cos(th));
      v.push_back({{x, y, z}, {x, y, z}});
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const auto a = static_cast<uint32_t>(i * (slices + 1) + j);
      const auto b = static_cast<uint32_t>(a + static_cast<uint32_t>(slices) + 1);
      idx.insert(idx.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
}

void unitCylinder(std::vector<Vertex>& v, std::vector<uint32_t>& idx, int slices) {
  for (int j = 0; j <= slices; ++j) {  // side
    const double ph = 2 * M_PI * j / slices;
    const float x = static_cast<float>(std::cos(ph)), y = static_cast<float>(std::sin(ph));
    v.push_back({{x, y, -0.5f}, {x, y, 0}});
    v.push_back({{x, y, 0.5f}, {x, y, 0}});
  }
  for (int j = 0; j < slices; ++j) {
    const auto a = static_cast<uint32_t>(2 * j);
    idx.insert(idx.end(), {a, a + 2, a + 1, a + 1, a + 2, a + 3});
  }
  for (int cap = 0; cap < 2; ++cap) {
    const float z = cap == 0 ? -0.5f : 0.5f, nz = cap == 0 ? -1.0f : 1.0f;
    const auto centre = static_cast<uint32_t>(v.size());
    v.push_back({{0, 0, z}, {0, 0, nz}});
    for (int j = 0; j <= slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      v.push_back(
          {{static_cast<float>(std::cos(ph)), static_cast<float>(std::sin(ph)), z}, {0, 0, nz}});
    }
    for (int j = 0; j < slices; ++j) {
      const auto a = centre + 1 + static_cast<uint32_t>(j);
      if (cap == 0)
        idx.insert(idx.end(), {centre, a + 1, a});
      else
        idx.insert(idx.end(), {centre, a, a + 1});
    }
  }
}

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::array<char, 2048> log{};
    glGetShaderInfoLog(s, static_cast<GLsizei>(log.size()), nullptr, log.data());
    throw RenderError(std::string("renderer: shader compilation failed: ") + log.data());
  }
  return s;
}

}  // namespace

struct OffscreenRenderer::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  std::array<GLuint, 2> programs{};  // plain, ball pattern
  std::array<GLint, 2> view_projection{-1, -1};
  std::array<GLint, 2> colour_transform{-1, -1}, colour_offset{-1, -1};
  std::array<Mesh, kMeshCount> meshes;  // by meshOf(Primitive), then the coarse ones
  GLuint instances = 0;                 // every view's instances, one buffer
  GLuint fbo = 0, colour = 0, depth = 0;
  int fbo_width = 0, fbo_height = 0;
  std::vector<Instance> all;                 // the scene's instances
  std::vector<std::array<float, 4>> bounds;  // their bounding spheres (x, y, z, r)
  std::vector<float> radius;                 // their meshes' scale (a sphere's, a capsule's radius)
  std::vector<size_t> batch_of;
  std::vector<size_t> view_order;  // views by height, for the atlas layout
  std::array<std::vector<uint32_t>, kBatchMesh.size()> visible;  // one view's, by batch
  std::vector<Instance> uploaded;  // per view, per batch, the visible instances
  std::vector<std::array<std::array<size_t, 2>, kBatchMesh.size()>> ranges;  // [view][batch]
  std::array<cv::Mat, 2> atlases;  // RGBA, every view top row first; alternating
  size_t current = 0;              // the last render's
  std::vector<cv::Rect> rects;     // each view's place in the atlas

  // Aims a mesh's per-instance attributes at instances [first, ...) of the buffer.
  void pointInstances(size_t first) const {
    const auto base = first * sizeof(Instance);
    for (GLuint c = 0; c < 4; ++c)
      glVertexAttribPointer(2 + c, 4, GL_FLOAT, GL_FALSE, sizeof(Instance),
                            reinterpret_cast<void*>(base + c * 4 * sizeof(float)));
    glVertexAttribPointer(6, 3, GL_FLOAT, GL_FALSE, sizeof(Instance),
                          reinterpret_cast<void*>(base + offsetof(Instance, colour)));
    glVertexAttribPointer(7, 1, GL_FLOAT, GL_FALSE, sizeof(Instance),
                          reinterpret_cast<void*>(base + offsetof(Instance, stretch)));
  }

  void openDisplay() {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) throw RenderError("renderer: EGL has no eglGetPlatformDisplayEXT");
    display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) return;
    // Second choice: the first EGL device (a GPU driver without Mesa's platform).
    auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[4];
    EGLint count = 0;
    if (query_devices && query_devices(4, devices, &count) && count > 0) {
      display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
      if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) return;
    }
    throw RenderError("renderer: no EGL display (surfaceless Mesa or device platform), EGL error " +
                      std::to_string(eglGetError()));
  }

  void createContext() {
    if (!eglBindAPI(EGL_OPENGL_API)) throw RenderError("renderer: eglBindAPI(OpenGL) failed");
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint n = 0;
    eglChooseConfig(display, config_attributes, &config, 1, &n);
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         3,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
    context = eglCreateContext(display, n > 0 ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT,
                               context_attributes);
    if (context == EGL_NO_CONTEXT)
      throw RenderError("renderer: no OpenGL 3.3 core context, EGL error " +
                        std::to_string(eglGetError()));
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
      throw RenderError("renderer: eglMakeCurrent without a surface failed");
  }

  void buildPrograms() {
    const std::array<const char*, 2> fragment{kPlainFragmentShader, kPatternFragmentShader};
    for (size_t i = 0; i < programs.size(); ++i) {
      const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
      const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment[i]);
      const GLuint program = glCreateProgram();
      glAttachShader(program, vs);
      glAttachShader(program, fs);
      glLinkProgram(program);
      glDeleteShader(vs);
      glDeleteShader(fs);
      GLint ok = 0;
      glGetProgramiv(program, GL_LINK_STATUS, &ok);
      if (!ok) throw RenderError("renderer: shader program did not link");
      programs[i] = program;
      view_projection[i] = glGetUniformLocation(program, "view_projection");
      colour_transform[i] = glGetUniformLocation(program, "colour_transform");
      colour_offset[i] = glGetUniformLocation(program, "colour_offset");
    }
  }

  void buildMesh(size_t mesh) {
    std::vector<Vertex> v;
    std::vector<uint32_t> idx;
    if (mesh == meshOf(Primitive::Box)) unitBox(v, idx);
    if (mesh == meshOf(Primitive::Sphere)) unitSphere(v, idx, 12, 8);
    if (mesh == meshOf(Primitive::CoarseSphere)) unitIcosahedron(v, idx);
    if (mesh == meshOf(Primitive::Quad)) unitQuad(v, idx);
    if (mesh == meshOf(Primitive::Cylinder)) unitCylinder(v, idx, 6);
    if (mesh == meshOf(Primitive::Capsule)) unitCapsule(v, idx, 6);
    if (mesh == kOctahedronMesh) unitOctahedron(v, idx);
    if (mesh == kThinCapsuleMesh) unitCapsule(v, idx, 3);
    Mesh& m = meshes[mesh];
    glGenVertexArrays(1, &m.vao);
    glBindVertexArray(m.vao);
    glGenBuffers(1, &m.vertices);
    glBindBuffer(GL_ARRAY_BUFFER, m.vertices);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(Vertex)), v.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                          reinterpret_cast<void*>(offsetof(Vertex, n)));
    glGenBuffers(1, &m.indices);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.indices);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(idx.size() * sizeof(uint32_t)),
                 idx.data(), GL_STATIC_DRAW);
    m.index_count = static_cast<GLsizei>(idx.size());
    // Per-instance attributes (model matrix columns, colour) come from the
    // shared instance buffer; pointInstances() aims them at a range.
    glBindBuffer(GL_ARRAY_BUFFER, instances);
    for (GLuint a = 2; a <= 7; ++a) {
      glEnableVertexAttribArray(a);
      glVertexAttribDivisor(a, 1);
    }
    glBindVertexArray(0);
  }

  void ensureFramebuffer(int width, int height) {
    if (fbo && width <= fbo_width && height <= fbo_height) return;
    if (fbo) {
      glDeleteFramebuffers(1, &fbo);
      glDeleteRenderbuffers(1, &colour);
      glDeleteRenderbuffers(1, &depth);
    }
    fbo_width = width;
    fbo_height = height;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &colour);
    glBindRenderbuffer(GL_RENDERBUFFER, colour);
    // RGBA: llvmpipe's native 32-bit layout renders and reads back faster than RGB.
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw RenderError("renderer: framebuffer " + std::to_string(width) + "x" +
                        std::to_string(height) + " is incomplete");
  }
};

OffscreenRenderer::OffscreenRenderer() : impl_(std::make_unique<Impl>()) {
  impl_->openDisplay();
  impl_->createContext();
  impl_->buildPrograms();
  glGenBuffers(1, &impl_->instances);
  for (size_t mesh = 0; mesh < kMeshCount; ++mesh) impl_->buildMesh(mesh);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
  // The projection flips y so that image rows come out top row first in
  // memory (no flip after the readback); that turns the winding around.
  glFrontFace(GL_CW);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
}

OffscreenRenderer::~OffscreenRenderer() {
  if (impl_->display == EGL_NO_DISPLAY) return;
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (impl_->context != EGL_NO_CONTEXT) eglDestroyContext(impl_->display, impl_->context);
  eglTerminate(impl_->display);
}

std::string OffscreenRenderer::glRenderer() const {
  const auto* s = glGetString(GL_RENDERER);
  return s ? reinterpret_cast<const char*>(s) : "";
}

namespace {

// World -> clip space for a view: OpenGL's camera looks down -z with y up,
// ours looks along x with z up; y is flipped so that row 0 in memory is the
// image's top row.
Eigen::Matrix4f viewProjection(const RenderView& v) {
  Eigen::Matrix4d gl_from_camera = Eigen::Matrix4d::Zero();
  gl_from_camera(0, 1) = -1.0;
  gl_from_camera(1, 2) = 1.0;
  gl_from_camera(2, 0) = -1.0;
  gl_from_camera(3, 3) = 1.0;
  const double w = v.width, h = v.height, n = v.near_clip, f = v.far_clip;
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  projection(0, 0) = 2 * v.fx / w;
  projection(0, 2) = 1 - 2 * v.cx / w;
  projection(1, 1) = -2 * v.fy / h;
  projection(1, 2) = 1 - 2 * v.cy / h;
  projection(2, 2) = -(f + n) / (f - n);
  projection(2, 3) = -2 * f * n / (f - n);
  projection(3, 2) = -1;
  return (projection * gl_from_camera * v.pose.inverse().matrix()).cast<float>();
}

// The view frustum's four side planes and the far plane in the world frame
// (inward normals), for culling whole instances by their bounding spheres.
struct Frustum {
  std::array<Eigen::Vector4f, 5> planes;
  explicit Frustum(const RenderView& v) {
    const Eigen::Matrix3d R = v.pose.linear();
    const Vec3 o = v.pose.translation();
    // Camera frame: x forward, y left, z up. Edges of the image in camera rays.
    const double left = v.cx / v.fx, right = (v.width - v.cx) / v.fx;
    const double top = v.cy / v.fy, bottom = (v.height - v.cy) / v.fy;
    const std::array<Vec3, 5> normals{Vec3(left, -1, 0), Vec3(right, 1, 0), Vec3(top, 0, -1),
                                      Vec3(bottom, 0, 1), Vec3(-1, 0, 0)};
    for (size_t i = 0; i < normals.size(); ++i) {
      const Vec3 n = R * normals[i].normalized();
      const double d = i < 4 ? -n.dot(o) : -n.dot(o + R * Vec3(v.far_clip, 0, 0));
      planes[i] = Eigen::Vector4f(float(n.x()), float(n.y()), float(n.z()), float(d));
    }
  }
  bool sees(const std::array<float, 4>& s) const {
    for (const auto& p : planes)
      if (p.x() * s[0] + p.y() * s[1] + p.z() * s[2] + p.w() < -s[3]) return false;
    return true;
  }
};

}  // namespace

void OffscreenRenderer::render(std::span<const DrawItem> scene, std::span<const RenderView> views) {
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  // Shelf packing of the views into one framebuffer, rows at most 4096 px
  // wide, tallest views first; a view no taller than the room left under the
  // last one placed in the row, and as wide, goes below it (two bottom-camera
  // views in the height of a top-camera one). The clear and the readback
  // cover the whole framebuffer: 22 robots' views fill 92 % of it (76 % in
  // rows of their own).
  const int max_row = 4096;
  m.rects.resize(views.size());
  std::vector<size_t>& order = m.view_order;
  order.resize(views.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const RenderView& v = views[i];
    if (v.width <= 0 || v.height <= 0 || v.width > max_row)
      throw RenderError("renderer: view " + std::to_string(i) + " has an invalid size");
    order[i] = i;
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return views[a].height > views[b].height; });
  int x = 0, y = 0, row_height = 0, width = 1, height = 1;
  cv::Rect last;  // the last view placed in this row
  for (size_t i : order) {
    const RenderView& v = views[i];
    if (last.width == v.width && last.y + last.height + v.height <= y + row_height) {
      m.rects[i] = cv::Rect(last.x, last.y + last.height, v.width, v.height);
    } else {
      if (x + v.width > max_row) {
        x = 0;
        y += row_height;
        row_height = 0;
      }
      m.rects[i] = cv::Rect(x, y, v.width, v.height);
      x += v.width;
      row_height = std::max(row_height, v.height);
    }
    last = m.rects[i];
    width = std::max(width, x);
    height = std::max(height, y + row_height);
  }
  m.ensureFramebuffer(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, m.fbo);

  // The scene's instances and bounding spheres, then per view the ones
  // inside its frustum, batch by batch, all in one buffer.
  m.all.clear();
  m.bounds.clear();
  m.batch_of.clear();
  m.radius.clear();
  for (const DrawItem& d : scene) {
    if (d.ground && d.shape != Primitive::Quad)
      throw RenderError("renderer: ground paint must be quads");
    Instance in{};
    std::copy(d.transform.data(), d.transform.data() + 16, in.model);
    in.colour[0] = d.colour.x();
    in.colour[1] = d.colour.y();
    in.colour[2] = d.colour.z();
    in.stretch = d.shape == Primitive::Capsule ? d.stretch : 0.0f;
    m.all.push_back(in);
    const Eigen::Matrix3f l = d.transform.block<3, 3>(0, 0);
    const float scale = std::max({l.col(0).norm(), l.col(1).norm(), l.col(2).norm()});
    m.bounds.push_back({d.transform(0, 3), d.transform(1, 3), d.transform(2, 3),
                        scale * unitRadius(d.shape, in.stretch)});
    m.batch_of.push_back(batchOf(d));
    m.radius.push_back(scale);
  }
  m.uploaded.clear();
  m.ranges.assign(views.size(), {});
  size_t triangles = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const Frustum frustum(views[i]);
    const Eigen::Vector3f eye = views[i].pose.translation().cast<float>();
    const auto focal = static_cast<float>(std::max(views[i].fx, views[i].fy));
    for (auto& list : m.visible) list.clear();
    for (size_t k = 0; k < m.all.size(); ++k) {  // scene order kept within a batch
      const auto& s = m.bounds[k];
      if (!frustum.sees(s)) continue;
      const float distance = (Eigen::Vector3f(s[0], s[1], s[2]) - eye).norm();
      const size_t b =
          levelOfDetail(m.batch_of[k], m.radius[k] * focal / std::max(distance, 1e-3f));
      m.visible[b].push_back(static_cast<uint32_t>(k));
    }
    for (size_t b = 0; b < kBatchMesh.size(); ++b) {
      m.ranges[i][b] = {m.uploaded.size(), m.visible[b].size()};
      for (uint32_t k : m.visible[b]) m.uploaded.push_back(m.all[k]);
      triangles +=
          m.visible[b].size() * static_cast<size_t>(m.meshes[kBatchMesh[b]].index_count / 3);
    }
  }
  glBindBuffer(GL_ARRAY_BUFFER, m.instances);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(m.uploaded.size() * sizeof(Instance)),
               m.uploaded.data(), GL_STREAM_DRAW);

  // One clear of the whole framebuffer in the colour space most views are
  // drawn in (llvmpipe clears whole tiles fast; a scissored clear per view
  // writes every pixel), then one of each view drawn in the other.
  const Eigen::Vector3f hall(0.35f, 0.35f, 0.38f);  // the hall around the field
  const auto yuv_views =
      static_cast<size_t>(std::count_if(views.begin(), views.end(), [](const RenderView& v) {
        return v.format == PixelFormat::Yuv;
      }));
  const PixelFormat cleared = 2 * yuv_views > views.size() ? PixelFormat::Yuv : PixelFormat::Rgb;
  const auto clearTo = [&](PixelFormat format) {
    const Eigen::Vector3f c = colourTransform(format)(hall);
    glClearColor(c.x(), c.y(), c.z(), 1.0f);
  };
  glDisable(GL_SCISSOR_TEST);
  clearTo(cleared);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_SCISSOR_TEST);
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i].format == cleared) continue;
    const cv::Rect& r = m.rects[i];
    glScissor(r.x, r.y, r.width, r.height);
    clearTo(views[i].format);
    glClear(GL_COLOR_BUFFER_BIT);
  }
  for (size_t i = 0; i < views.size(); ++i) {
    const cv::Rect& r = m.rects[i];
    glViewport(r.x, r.y, r.width, r.height);
    glScissor(r.x, r.y, r.width, r.height);
    const Eigen::Matrix4f vp = viewProjection(views[i]);
    const ColourTransform colours = colourTransform(views[i].format);
    for (size_t b = 0; b < kBatchMesh.size(); ++b) {
      const auto [first, count] = m.ranges[i][b];
      if (count == 0) continue;
      if (b == kGroundBatch)
        glDisable(GL_DEPTH_TEST);
      else
        glEnable(GL_DEPTH_TEST);
      const size_t program = b == kPatternBatch ? 1 : 0;
      glUseProgram(m.programs[program]);
      glUniformMatrix4fv(m.view_projection[program], 1, GL_FALSE, vp.data());
      glUniformMatrix3fv(m.colour_transform[program], 1, GL_FALSE, colours.transform.data());
      glUniform3fv(m.colour_offset[program], 1, colours.offset.data());
      const Mesh& mesh = m.meshes[kBatchMesh[b]];
      glBindVertexArray(mesh.vao);
      m.pointInstances(first);
      glDrawElementsInstanced(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr,
                              static_cast<GLsizei>(count));
    }
  }
  glFinish();
  timing_.draw_ms = msSince(t0);

  // One readback; every view is a region of it, already top row first.
  const auto t1 = Clock::now();
  m.current ^= 1;
  cv::Mat& atlas = m.atlases[m.current];
  atlas.create(height, width, CV_8UC4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, atlas.data);
  timing_.readback_ms = msSince(t1);
  timing_.atlas_width = width;
  timing_.atlas_height = height;
  timing_.triangles = triangles;
  timing_.triangles_per_view = views.empty() ? 0 : triangles / views.size();
}

cv::Mat OffscreenRenderer::image(size_t view) const {
  return impl_->atlases[impl_->current](impl_->rects.at(view));
}

void OffscreenRenderer::render(std::span<const DrawItem> scene, std::span<const RenderView> views,
                               std::vector<cv::Mat>& images) {
  render(scene, views);
  images.resize(views.size());
  for (size_t i = 0; i < views.size(); ++i)
    cv::cvtColor(image(i), images[i], cv::COLOR_RGBA2RGB);  // drops the 4th channel
}

RenderView pinholeView(const Pose& pose, int width, int height, double horizontal_fov,
                       double vertical_fov) {
  RenderView v;
  v.pose = pose;
  v.width = width;
  v.height = height;
  v.fx = 0.5 * width / std::tan(0.5 * horizontal_fov);
  v.fy = 0.5 * height / std::tan(0.5 * vertical_fov);
  v.cx = 0.5 * width;
  v.cy = 0.5 * height;
  return v;
}

bool projectPoint(const RenderView& view, const Vec3& world_point, double& u, double& v) {
  // The pose is rigid: its inverse is the transposed rotation (no general 3x3 inverse).
  return projectCameraPoint(view, view.pose.inverse(Eigen::Isometry) * world_point, u, v);
}

bool projectCameraPoint(const RenderView& view, const Vec3& p, double& u, double& v) {
  // p in the camera frame: x forward, y left, z up.
  if (p.x() <= 1e-9) return false;
  u = view.cx - view.fx * p.y() / p.x();
  v = view.cy - view.fy * p.z() / p.x();
  return true;
}

namespace {

// One row of packed YUV (Y U V per pixel, then a fourth byte that is skipped
// when kChannels is 4) as YUYV: each pixel pair keeps its two Y and shares
// the rounded means of its U and of its V. 32 pixels at a time with OpenCV's
// universal intrinsics, the rest one pair at a time.
// `in`: Y, U (Cb), V (Cr) per pixel, or Y, V, U with kVFirst (OpenCV's YCrCb order).
template <int kChannels, bool kVFirst = false>
void packYuyv(const uint8_t* in, uint8_t* out, int cols) {
  static_assert(kChannels == 3 || kChannels == 4);
  constexpr int kU = kVFirst ? 2 : 1, kV = kVFirst ? 1 : 2;
  int c = 0;
#if CV_SIMD128
  const cv::v_uint16x8 low_byte = cv::v_setall_u16(0x00ff);
  const auto even = [&](const cv::v_uint8x16& a) { return cv::v_reinterpret_as_u16(a) & low_byte; };
  const auto odd = [](const cv::v_uint8x16& a) { return cv::v_reinterpret_as_u16(a) >> 8; };
  for (; c + 32 <= cols; c += 32, in += 32 * kChannels, out += 64) {
    cv::v_uint8x16 y0, u0, v0, y1, u1, v1;
    if constexpr (kChannels == 3) {
      cv::v_load_deinterleave(in, y0, u0, v0);
      cv::v_load_deinterleave(in + 48, y1, u1, v1);
    } else {
      cv::v_uint8x16 a0, a1;
      cv::v_load_deinterleave(in, y0, u0, v0, a0);
      cv::v_load_deinterleave(in + 64, y1, u1, v1, a1);
    }
    if constexpr (kVFirst) {
      std::swap(u0, v0);
      std::swap(u1, v1);
    }
    const cv::v_uint8x16 y_even = cv::v_pack(even(y0), even(y1));
    const cv::v_uint8x16 y_odd = cv::v_pack(odd(y0), odd(y1));
    const cv::v_uint8x16 u = cv::v_rshr_pack<1>(even(u0) + odd(u0), even(u1) + odd(u1));
    const cv::v_uint8x16 v = cv::v_rshr_pack<1>(even(v0) + odd(v0), even(v1) + odd(v1));
    cv::v_store_interleave(out, y_even, u, y_odd, v);
  }
#endif
  for (; c < cols; c += 2, in += 2 * kChannels, out += 4) {
    out[0] = in[0];
    out[1] = static_cast<uint8_t>((in[kU] + in[kChannels + kU] + 1) >> 1);
    out[2] = in[kChannels];
    out[3] = static_cast<uint8_t>((in[kV] + in[kChannels + kV] + 1) >> 1);
  }
}

void checkYuyvInput(const cv::Mat& in, const char* function) {
  if ((in.type() != CV_8UC3 && in.type() != CV_8UC4) || in.cols % 2 != 0)
    throw std::invalid_argument(std::string(function) +
                                ": 8-bit three or four channels with an even width expected");
}

}  // namespace

cv::Mat rgbToYuyv(const cv::Mat& rgb) {
  cv::Mat out;
  rgbToYuyv(rgb, out);
  return out;
}

void rgbToYuyv(const cv::Mat& rgb, cv::Mat& out) {
  checkYuyvInput(rgb, "rgbToYuyv");
  out.create(rgb.rows, rgb.cols, CV_8UC2);  // kept if it already is that (caller's memory)
  // Strips of rows, each converted by OpenCV into a small YUV buffer that
  // stays in cache while it is packed (a whole-image YUV buffer made the
  // conversion a third slower).
  const int strip = 16;
  auto body = [&](const cv::Range& strips) {
    cv::Mat yuv;
    for (int s = strips.start; s < strips.end; ++s) {
      const int r0 = s * strip, r1 = std::min(r0 + strip, rgb.rows);
      cv::cvtColor(rgb.rowRange(r0, r1), yuv, cv::COLOR_RGB2YCrCb);  // reads 3 or 4 channels
      for (int r = r0; r < r1; ++r)
        packYuyv<3, true>(yuv.ptr<uint8_t>(r - r0), out.ptr<uint8_t>(r), rgb.cols);
    }
  };
  cv::parallel_for_(cv::Range(0, (rgb.rows + strip - 1) / strip), body);
}

void yuvToYuyv(const cv::Mat& yuv, cv::Mat& out) {
  checkYuyvInput(yuv, "yuvToYuyv");
  out.create(yuv.rows, yuv.cols, CV_8UC2);
  const bool four = yuv.channels() == 4;
  cv::parallel_for_(cv::Range(0, yuv.rows), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      if (four)
        packYuyv<4>(yuv.ptr<uint8_t>(r), out.ptr<uint8_t>(r), yuv.cols);
      else
        packYuyv<3>(yuv.ptr<uint8_t>(r), out.ptr<uint8_t>(r), yuv.cols);
    }
  });
}

}  // namespace simsoccer::engine

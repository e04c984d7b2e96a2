#include "simsoccer/engine/offscreen_renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>

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
uniform mat4 view_projection;
flat out vec3 lit_colour;
out vec3 object_position;
void main() {
  gl_Position = view_projection * model * vec4(position, 1.0);
  vec3 n = normalize(mat3(model) * normal);
  lit_colour = colour * (0.6 + 0.4 * max(dot(n, normalize(vec3(0.3, 0.2, 1.0))), 0.0));
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
in vec3 object_position;
out vec4 fragment;
void main() {
  const float g = 1.618034;
  vec3 a = abs(normalize(object_position));
  float best = max(max(dot(a, normalize(vec3(0.0, 1.0, g))), dot(a, normalize(vec3(1.0, g, 0.0)))),
                   dot(a, normalize(vec3(g, 0.0, 1.0))));
  fragment = vec4(best > 0.93 ? vec3(0.05) : lit_colour, 1.0);
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
};

// Draw batches: one per unit mesh, the ball's patterned sphere apart (its own
// fragment program). Drawn in this order: robots' parts (usually nearest the
// camera) first, the ground last, so hidden ground pixels fail the early depth test.
constexpr std::array<Primitive, 6> kBatchMesh{Primitive::CoarseSphere, Primitive::Cylinder,
                                              Primitive::Sphere,       Primitive::Sphere,
                                              Primitive::Box,          Primitive::Quad};
constexpr size_t kPatternBatch = 3;

constexpr float kIcosahedronScale = 2.0f / (1.0f + 0.7946545f);

size_t batchOf(const DrawItem& d) {
  if (d.ball_pattern) return kPatternBatch;
  switch (d.shape) {
    case Primitive::CoarseSphere:
      return 0;
    case Primitive::Cylinder:
      return 1;
    case Primitive::Sphere:
      return 2;
    case Primitive::Box:
      return 4;
    case Primitive::Quad:
      return 5;
  }
  return 4;
}

// Radius of the unit mesh's bounding sphere (box corners at sqrt(3)/2; the
// cylinder's rim at sqrt(1 + 0.25)).
float unitRadius(Primitive p) {
  switch (p) {
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
      Eigen::Vector3f(-1, g, 0), Eigen::Vector3f(1, g, 0),   Eigen::Vector3f(-1, -g, 0),
      Eigen::Vector3f(1, -g, 0), Eigen::Vector3f(0, -1, g),  Eigen::Vector3f(0, 1, g),
      Eigen::Vector3f(0, -1, -g), Eigen::Vector3f(0, 1, -g), Eigen::Vector3f(g, 0, -1),
      Eigen::Vector3f(g, 0, 1),  Eigen::Vector3f(-g, 0, -1), Eigen::Vector3f(-g, 0, 1)};
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
  std::array<Mesh, 5> meshes;  // by Primitive
  GLuint instances = 0;        // every view's instances, one buffer
  GLuint fbo = 0, colour = 0, depth = 0;
  int fbo_width = 0, fbo_height = 0;
  std::vector<Instance> all;                 // the scene's instances
  std::vector<std::array<float, 4>> bounds;  // their bounding spheres (x, y, z, r)
  std::vector<size_t> batch_of;
  std::vector<Instance> uploaded;  // per view, per batch, the visible instances
  std::vector<std::array<std::array<size_t, 2>, kBatchMesh.size()>> ranges;  // [view][batch]
  cv::Mat atlas;                // RGBA, every view top row first
  std::vector<cv::Rect> rects;  // each view's place in the atlas

  // Aims a mesh's per-instance attributes at instances [first, ...) of the buffer.
  void pointInstances(size_t first) const {
    const auto base = first * sizeof(Instance);
    for (GLuint c = 0; c < 4; ++c)
      glVertexAttribPointer(2 + c, 4, GL_FLOAT, GL_FALSE, sizeof(Instance),
                            reinterpret_cast<void*>(base + c * 4 * sizeof(float)));
    glVertexAttribPointer(6, 3, GL_FLOAT, GL_FALSE, sizeof(Instance),
                          reinterpret_cast<void*>(base + offsetof(Instance, colour)));
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
    }
  }

  void buildMesh(Primitive p) {
    std::vector<Vertex> v;
    std::vector<uint32_t> idx;
    if (p == Primitive::Box) unitBox(v, idx);
    if (p == Primitive::Sphere) unitSphere(v, idx, 12, 8);
    if (p == Primitive::CoarseSphere) unitIcosahedron(v, idx);
    if (p == Primitive::Quad) unitQuad(v, idx);
    if (p == Primitive::Cylinder) unitCylinder(v, idx, 6);
    Mesh& m = meshes[static_cast<size_t>(p)];
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
    for (GLuint a = 2; a <= 6; ++a) {
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
  for (Primitive p :
       {Primitive::Box, Primitive::Sphere, Primitive::CoarseSphere, Primitive::Cylinder,
        Primitive::Quad})
    impl_->buildMesh(p);
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
  // Shelf packing of the views into one framebuffer, rows at most 4096 px wide.
  const int max_row = 4096;
  m.rects.resize(views.size());
  int x = 0, y = 0, row_height = 0, width = 1, height = 1;
  for (size_t i = 0; i < views.size(); ++i) {
    const RenderView& v = views[i];
    if (v.width <= 0 || v.height <= 0 || v.width > max_row)
      throw RenderError("renderer: view " + std::to_string(i) + " has an invalid size");
    if (x + v.width > max_row) {
      x = 0;
      y += row_height;
      row_height = 0;
    }
    m.rects[i] = cv::Rect(x, y, v.width, v.height);
    x += v.width;
    row_height = std::max(row_height, v.height);
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
  for (const DrawItem& d : scene) {
    Instance in{};
    std::copy(d.transform.data(), d.transform.data() + 16, in.model);
    in.colour[0] = d.colour.x();
    in.colour[1] = d.colour.y();
    in.colour[2] = d.colour.z();
    m.all.push_back(in);
    const Eigen::Matrix3f l = d.transform.block<3, 3>(0, 0);
    const float scale = std::max({l.col(0).norm(), l.col(1).norm(), l.col(2).norm()});
    m.bounds.push_back(
        {d.transform(0, 3), d.transform(1, 3), d.transform(2, 3), scale * unitRadius(d.shape)});
    m.batch_of.push_back(batchOf(d));
  }
  m.uploaded.clear();
  m.ranges.assign(views.size(), {});
  size_t triangles = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const Frustum frustum(views[i]);
    for (size_t b = 0; b < kBatchMesh.size(); ++b) {
      m.ranges[i][b][0] = m.uploaded.size();
      for (size_t k = 0; k < m.all.size(); ++k)
        if (m.batch_of[k] == b && frustum.sees(m.bounds[k])) m.uploaded.push_back(m.all[k]);
      m.ranges[i][b][1] = m.uploaded.size() - m.ranges[i][b][0];
      triangles +=
          m.ranges[i][b][1] *
          static_cast<size_t>(m.meshes[static_cast<size_t>(kBatchMesh[b])].index_count / 3);
    }
  }
  glBindBuffer(GL_ARRAY_BUFFER, m.instances);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(m.uploaded.size() * sizeof(Instance)),
               m.uploaded.data(), GL_STREAM_DRAW);

  // One clear of the whole framebuffer (llvmpipe clears whole tiles fast;
  // a scissored clear per view writes every pixel).
  glDisable(GL_SCISSOR_TEST);
  glClearColor(0.35f, 0.35f, 0.38f, 1.0f);  // the hall around the field
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_SCISSOR_TEST);
  for (size_t i = 0; i < views.size(); ++i) {
    const cv::Rect& r = m.rects[i];
    glViewport(r.x, r.y, r.width, r.height);
    glScissor(r.x, r.y, r.width, r.height);
    const Eigen::Matrix4f vp = viewProjection(views[i]);
    for (size_t b = 0; b < kBatchMesh.size(); ++b) {
      const auto [first, count] = m.ranges[i][b];
      if (count == 0) continue;
      const size_t program = b == kPatternBatch ? 1 : 0;
      glUseProgram(m.programs[program]);
      glUniformMatrix4fv(m.view_projection[program], 1, GL_FALSE, vp.data());
      const Mesh& mesh = m.meshes[static_cast<size_t>(kBatchMesh[b])];
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
  m.atlas.create(height, width, CV_8UC4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, m.atlas.data);
  timing_.readback_ms = msSince(t1);
  timing_.atlas_width = width;
  timing_.atlas_height = height;
  timing_.triangles = triangles;
  timing_.triangles_per_view = views.empty() ? 0 : triangles / views.size();
}

cv::Mat OffscreenRenderer::image(size_t view) const {
  return impl_->atlas(impl_->rects.at(view));
}

void OffscreenRenderer::render(std::span<const DrawItem> scene, std::span<const RenderView> views,
                               std::vector<cv::Mat>& images) {
  render(scene, views);
  images.resize(views.size());
  for (size_t i = 0; i < views.size(); ++i) cv::cvtColor(image(i), images[i], cv::COLOR_RGBA2RGB);
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
  const Vec3 p = view.pose.inverse() * world_point;  // camera frame: x forward, y left, z up
  if (p.x() <= 1e-9) return false;
  u = view.cx - view.fx * p.y() / p.x();
  v = view.cy - view.fy * p.z() / p.x();
  return true;
}

cv::Mat rgbToYuyv(const cv::Mat& rgb) {
  cv::Mat out;
  rgbToYuyv(rgb, out);
  return out;
}

void rgbToYuyv(const cv::Mat& rgb, cv::Mat& out) {
  if ((rgb.type() != CV_8UC3 && rgb.type() != CV_8UC4) || rgb.cols % 2 != 0)
    throw std::invalid_argument("rgbToYuyv: 8-bit RGB or RGBA with an even width expected");
  cv::Mat yuv;
  cv::cvtColor(rgb, yuv, cv::COLOR_RGB2YUV);  // reads 3 or 4 channels, writes 3
  out.create(rgb.rows, rgb.cols, CV_8UC2);  // kept if it already is that (caller's memory)
  cv::parallel_for_(cv::Range(0, rgb.rows), [&](const cv::Range& rows) {
    for (int r = rows.start; r < rows.end; ++r) {
      const auto* in = yuv.ptr<cv::Vec3b>(r);
      auto* o = out.ptr<uint8_t>(r);
      for (int c = 0; c < rgb.cols; c += 2) {
        const cv::Vec3b a = in[c], b = in[c + 1];
        o[2 * c + 0] = a[0];
        o[2 * c + 1] = static_cast<uint8_t>((a[1] + b[1] + 1) / 2);
        o[2 * c + 2] = b[0];
        o[2 * c + 3] = static_cast<uint8_t>((a[2] + b[2] + 1) / 2);
      }
    }
  });
}

}  // namespace simsoccer::engine

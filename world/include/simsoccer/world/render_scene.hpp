// The world as the renderer sees it: field, lines, goals, ball and robots as
// instanced unit primitives, and the robots' camera views.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "simsoccer/engine/offscreen_renderer.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::world {

// Colours (linear RGB): the SPL's green carpet and white lines, grey Naos
// with their team's jersey on the torso.
struct SceneColours {
  Eigen::Vector3f carpet{0.10f, 0.50f, 0.12f};
  Eigen::Vector3f line{0.95f, 0.95f, 0.95f};
  Eigen::Vector3f goal{0.97f, 0.97f, 0.97f};
  Eigen::Vector3f net{0.80f, 0.80f, 0.80f};
  Eigen::Vector3f floor{0.30f, 0.28f, 0.25f};
  Eigen::Vector3f robot{0.78f, 0.78f, 0.80f};
  Eigen::Vector3f ball{0.97f, 0.97f, 0.97f};
  std::vector<Eigen::Vector3f> jerseys{{0.10f, 0.20f, 0.90f}, {0.90f, 0.10f, 0.10f}};  // per team
  // Per robot (RobotId), the LED colours its software set: chest, left eye,
  // right eye (none or a missing entry: the LEDs are not drawn).
  struct Leds {
    Eigen::Vector3f chest, left_eye, right_eye;
  };
  std::vector<std::optional<Leds>> leds;
};

// The whole scene of the world's current state (appends to `items`).
void buildRenderScene(const World& world, std::vector<engine::DrawItem>& items,
                      const SceneColours& colours = {});

// A camera pose at `position` looking at `target` (camera x forward, y left,
// z up; the horizon level).
engine::Pose lookAtPose(const Vec3& position, const Vec3& target);

// A robot's camera (a camera sensor of its model: "CameraTop" on a Nao) as
// a view at its current head pose, with the model's field of view; throws
// std::invalid_argument if the model has no such camera.
engine::RenderView robotCameraView(const World& world, RobotId r, const std::string& camera,
                                   int width, int height);
engine::RenderView robotCameraView(const World& world, RobotId r,
                                   const robots::SensorFrame& camera, int width, int height);
// The camera frame alone (x forward, y left, z up) in the field: a view's pose.
engine::Pose robotCameraPose(const World& world, RobotId r, const robots::SensorFrame& camera);

}  // namespace simsoccer::world

// Keyframe motions (get-up from the front or the back, ...) as data: a
// sequence of whole-body joint targets, each reached from the one before
// over its duration (smoothstep or linear), the first from wherever the
// joints are when the motion starts. Files: configs/motions/*.yaml.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::agents {

struct Keyframe {
  double duration = 0.5;         // s to reach this frame from the previous one
  double stiffness = 1.0;        // 0..1, every joint while moving to this frame
  std::vector<double> position;  // per body joint, rad
};

struct KeyframeMotion {
  std::string name;
  // How a frame is approached: smoothstep (each frame reached at rest, for a
  // few long frames) or linear (constant speed within a frame, so a dense
  // sequence of short frames moves without stopping at each).
  enum class Interpolation { Smooth, Linear } interpolation = Interpolation::Smooth;
  // Where the motion leaves the robot: standing (a get-up), or lying on its
  // front or back (a roll, after which the get-up from that side runs).
  enum class Ends { Standing, Front, Back } ends = Ends::Standing;
  std::vector<Keyframe> frames;
  double duration() const;
};

// Reads a motion for `model`: interpolation: smooth|linear (default smooth),
// ends: standing|front|back (default standing), frames: [{duration,
// stiffness, pose: NAME (a pose of the robot model), joints: {Name: rad, ...}}]. A frame starts
// from the previous frame (the first from the model's `stand` pose) or from its `pose`, then sets
// its `joints`; mimic joints follow their masters. Throws engine::ConfigError (file, key, reason).
KeyframeMotion loadKeyframeMotion(const std::filesystem::path& file,
                                  const robots::RobotModel& model);

// Plays one motion: start() with the measured joint angles, then update()
// every control period until done().
class KeyframePlayer {
 public:
  void start(const KeyframeMotion& motion, const std::vector<double>& measured);
  bool active() const { return motion_ != nullptr; }
  // The motion playing, or the last one played.
  const KeyframeMotion* motion() const { return last_; }
  double elapsed() const { return t_; }
  // Advances by dt and writes targets (per body joint) and the stiffness.
  void update(double dt, std::vector<double>& targets, double& stiffness);

 private:
  const KeyframeMotion* motion_ = nullptr;
  const KeyframeMotion* last_ = nullptr;
  std::vector<double> from_;
  double t_ = 0.0;
};

}  // namespace simsoccer::agents

// Camera images of LoLA robots for team code, as the Webots LoLA controller
// serves them (team-side adapters such as Bembelbots' TCPVideoSource read it
// unchanged): one TCP server per camera; each frame is a 16-byte header
// (struct "8sHBBHH", little-endian: "wbimage\0", tick u16, camera u8, bytes
// per pixel u8 = 2, width u16, height u16) and the raw YUYV image. A camera
// on a real Nao delivers YUYV at 30 fps; the scenario's cameras set the
// rate and sizes (640 x 480 top, 320 x 240 bottom by default).
//
// In lockstep a frame due at a tick is written before the world steps past
// it: as a command source (without robots) the streams flush the camera
// system in the observe stage.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/camera_system.hpp"

namespace simsoccer::lola {

inline constexpr std::size_t kImageHeaderBytes = 16;
std::array<uint8_t, kImageHeaderBytes> imageHeader(uint64_t tick, world::CameraId camera, int width,
                                                   int height);

struct ImagePorts {
  world::RobotId robot = 0;
  uint16_t top = 0, bottom = 0;  // TCP ports (0: any free one)
};

struct ImageStreamStats {
  uint64_t frames_sent = 0, frames_dropped = 0, clients = 0;
};

class ImageStreams : public sim::CommandSource {
 public:
  // Opens a server per camera of each robot and joins `sim` as an image
  // sink and a source (it must outlive the periods it is part of). Throws std::runtime_error naming a port that cannot be bound, or
  // std::invalid_argument when the scenario's cameras are off or not YUYV.
  ImageStreams(sim::Simulation& sim, const std::vector<ImagePorts>& robots,
               const std::string& bind = "127.0.0.1");
  ~ImageStreams() override;

  void observe(const sim::Observation&) override;
  void collect(uint64_t, sim::CommandGate&, std::span<sim::CommandSlot>) override {}

  // The bound port of robot i's camera (in the order given).
  uint16_t port(std::size_t i, world::CameraId camera) const;
  ImageStreamStats stats(std::size_t i, world::CameraId camera) const;

 private:
  struct Server;
  void deliver(const world::CameraImage& image);  // conversion thread
  sim::Simulation& sim_;
  std::vector<ImagePorts> robots_;
  std::vector<std::unique_ptr<Server>> servers_;  // 2 per robot: top, bottom
  mutable std::mutex mutex_;
};

}  // namespace simsoccer::lola

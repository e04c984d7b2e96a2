#include "simsoccer/lola/image_stream.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace simsoccer::lola {

std::array<uint8_t, kImageHeaderBytes> imageHeader(uint64_t tick, world::CameraId camera, int width,
                                                   int height) {
  std::array<uint8_t, kImageHeaderBytes> h{};
  std::memcpy(h.data(), "wbimage", 8);  // with its terminating zero
  const auto u16 = [&](std::size_t at, uint32_t v) {
    h[at] = static_cast<uint8_t>(v & 0xff);
    h[at + 1] = static_cast<uint8_t>((v >> 8) & 0xff);
  };
  u16(8, static_cast<uint32_t>(tick & 0xffff));  // the Webots controller's u16 cycle counter
  h[10] = static_cast<uint8_t>(camera);
  h[11] = 2;  // YUYV: 2 bytes per pixel
  u16(12, static_cast<uint32_t>(width));
  u16(14, static_cast<uint32_t>(height));
  return h;
}

struct ImageStreams::Server {
  int listen_fd = -1;
  uint16_t port = 0;
  struct Client {
    int fd = -1;
    std::vector<uint8_t> unsent;
  };
  std::vector<Client> clients;
  ImageStreamStats stats;
  // Frames a client may have unsent before new ones are dropped (whole), and
  // clients per camera (each may hold that much memory).
  static constexpr std::size_t kQueue = 3;
  static constexpr std::size_t kMaxClients = 4;

  Server(const std::string& bind, uint16_t wanted) {
    listen_fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const int yes = 1;
    ::setsockopt(listen_fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(wanted);
    if (::inet_pton(AF_INET, bind.c_str(), &a.sin_addr) != 1 ||
        ::bind(listen_fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::listen(listen_fd, 4) != 0) {
      const std::string why = std::strerror(errno);
      ::close(listen_fd);
      throw std::runtime_error("lola images: cannot listen on " + bind + ":" +
                               std::to_string(wanted) + ": " + why);
    }
    socklen_t len = sizeof a;
    ::getsockname(listen_fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~Server() {
    for (Client& c : clients) ::close(c.fd);
    ::close(listen_fd);
  }
  void accept() {
    for (int fd; (fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC)) >= 0;) {
      if (clients.size() >= kMaxClients) {
        ::close(fd);
        continue;
      }
      const int yes = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
      clients.push_back({fd, {}});
      ++stats.clients;
    }
  }
  // False when the client went away.
  static bool flush(Client& c) {
    while (!c.unsent.empty()) {
      const ssize_t n = ::send(c.fd, c.unsent.data(), c.unsent.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
      if (n > 0) {
        c.unsent.erase(c.unsent.begin(), c.unsent.begin() + n);
        continue;
      }
      return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR);
    }
    return true;
  }
  // Writes what is unsent, waiting for each client until `deadline` (a
  // client still behind then keeps its tail for later); drops clients gone.
  void flushAll(std::chrono::steady_clock::time_point deadline) {
    for (std::size_t i = 0; i < clients.size();) {
      Client& c = clients[i];
      bool alive = flush(c);
      while (alive && !c.unsent.empty()) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        pollfd p{c.fd, POLLOUT, 0};
        if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
        alive = flush(c);
      }
      if (!alive) {
        ::close(c.fd);
        clients.erase(clients.begin() + static_cast<long>(i));
        continue;
      }
      ++i;
    }
  }
  void send(const world::CameraImage& image) {
    accept();
    const auto header = imageHeader(image.tick, image.camera, image.view.width, image.view.height);
    const std::size_t frame = header.size() + image.data.size();
    for (std::size_t i = 0; i < clients.size();) {
      Client& c = clients[i];
      bool alive = flush(c);
      if (alive && c.unsent.size() + frame <= kQueue * frame) {
        c.unsent.insert(c.unsent.end(), header.begin(), header.end());
        c.unsent.insert(c.unsent.end(), image.data.begin(), image.data.end());
        ++stats.frames_sent;
        alive = flush(c);
      } else if (alive) {
        ++stats.frames_dropped;  // the client is more than the queue behind
      }
      if (!alive) {
        ::close(c.fd);
        clients.erase(clients.begin() + static_cast<long>(i));
        continue;
      }
      ++i;
    }
  }
};

ImageStreams::ImageStreams(sim::Simulation& sim, const std::vector<ImagePorts>& robots,
                           const std::string& bind)
    : sim_(sim), robots_(robots) {
  const world::CameraSettings& cams = sim.world().scenario().cameras;
  if (!cams.enabled)
    throw std::invalid_argument("lola images: the scenario '" + sim.world().scenario().name +
                                "' has no cameras (cameras: enabled: true)");
  if (cams.encoding != "yuyv")
    throw std::invalid_argument("lola images: the cameras must deliver yuyv (scenario '" +
                                sim.world().scenario().name + "' has " + cams.encoding + ")");
  for (const ImagePorts& r : robots_) {
    servers_.push_back(std::make_unique<Server>(bind, r.top));
    servers_.push_back(std::make_unique<Server>(bind, r.bottom));
  }
  sim.addImageSink([this](const world::CameraImage& image) { deliver(image); });
  sim.addSource(*this);
}

ImageStreams::~ImageStreams() {
  // Images still queued are delivered now, while this sink exists.
  sim_.flushCameras();
}

void ImageStreams::deliver(const world::CameraImage& image) {
  if (image.encoding != world::ImageEncoding::Yuyv || image.camera == world::CameraId::Spectator)
    return;
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < robots_.size(); ++i)
    if (robots_[i].robot == image.robot)
      servers_[2 * i + (image.camera == world::CameraId::Top ? 0 : 1)]->send(image);
}

void ImageStreams::observe(const sim::Observation&) {
  // Lockstep: the images of this tick are rendered and written before the
  // world steps past it (a client too slow for that keeps the rest for
  // later, and loses frames once three are queued). Real time: images go
  // out as they are rendered.
  const bool lockstep = sim_.config().lockstep;
  if (lockstep) sim_.flushCameras();  // delivers on this thread's watch (deliver() locks)
  std::lock_guard lock(mutex_);
  for (auto& s : servers_) s->accept();
  if (!lockstep) return;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  for (auto& s : servers_) s->flushAll(deadline);
}

uint16_t ImageStreams::port(std::size_t i, world::CameraId camera) const {
  return servers_.at(2 * i + (camera == world::CameraId::Top ? 0 : 1))->port;
}

ImageStreamStats ImageStreams::stats(std::size_t i, world::CameraId camera) const {
  std::lock_guard lock(mutex_);
  return servers_.at(2 * i + (camera == world::CameraId::Top ? 0 : 1))->stats;
}

}  // namespace simsoccer::lola

#include "simsoccer/referee/gamecontroller.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "packet_io.hpp"

namespace simsoccer::referee {
std::array<uint8_t, kControlSize> encode(const ControlData& d) {
  std::array<uint8_t, kControlSize> b{};
  Out o(b);
  o.bytes(d.true_data ? "RGTD" : "RGme", 4);
  o.u8(gc::kControlVersion);
  o.u8(d.packet_number);
  o.u8(d.players_per_team);
  o.u8(d.competition_phase);
  o.u8(d.competition_type);
  o.u8(d.game_phase);
  o.u8(d.state);
  o.u8(d.set_play);
  o.u8(d.first_half);
  o.u8(d.kicking_team);
  o.i16(d.secs_remaining);
  o.i16(d.secondary_time);
  for (const TeamInfo& t : d.teams) writeTeam(o, t, gc::kControlVersion);
  return b;
}

ControlData decodeControl(std::span<const uint8_t> bytes) {
  if (bytes.size() != kControlSize)
    throw PacketError("control packet: " + std::to_string(bytes.size()) + " bytes, expected " +
                      std::to_string(kControlSize));
  const bool rgme = std::memcmp(bytes.data(), "RGme", 4) == 0;
  const bool rgtd = std::memcmp(bytes.data(), "RGTD", 4) == 0;
  if (!rgme && !rgtd) throw PacketError("control packet: header is not RGme or RGTD");
  In in(bytes);
  for (int i = 0; i < 4; ++i) in.u8();
  const uint8_t version = in.u8();
  if (version != gc::kControlVersion)
    throw PacketError("control packet: version " + std::to_string(version) + ", expected 18");
  ControlData d;
  d.true_data = rgtd;
  d.packet_number = in.u8();
  d.players_per_team = in.u8();
  d.competition_phase = in.u8();
  d.competition_type = in.u8();
  d.game_phase = in.u8();
  d.state = in.u8();
  d.set_play = in.u8();
  d.first_half = in.u8();
  d.kicking_team = in.u8();
  d.secs_remaining = in.i16();
  d.secondary_time = in.i16();
  for (TeamInfo& t : d.teams) t = readTeam(in, gc::kControlVersion);
  if (d.game_phase > 3)
    throw PacketError("control packet: gamePhase " + std::to_string(d.game_phase));
  if (d.state > 5) throw PacketError("control packet: state " + std::to_string(d.state));
  if (d.set_play > 5) throw PacketError("control packet: setPlay " + std::to_string(d.set_play));
  return d;
}

std::array<uint8_t, kReturnSize> encode(const ReturnData& d) {
  std::array<uint8_t, kReturnSize> b{};
  Out o(b);
  o.bytes("RGrt", 4);
  o.u8(gc::kReturnVersion);
  o.u8(d.player_num);
  o.u8(d.team_num);
  o.u8(d.fallen);
  for (float v : d.pose) o.f32(v);
  o.f32(d.ball_age);
  for (float v : d.ball) o.f32(v);
  return b;
}

ReturnData decodeReturn(std::span<const uint8_t> bytes) {
  if (bytes.size() != kReturnSize)
    throw PacketError("return packet: " + std::to_string(bytes.size()) + " bytes, expected 32");
  if (std::memcmp(bytes.data(), "RGrt", 4) != 0)
    throw PacketError("return packet: header is not RGrt");
  In in(bytes);
  for (int i = 0; i < 4; ++i) in.u8();
  const uint8_t version = in.u8();
  if (version != gc::kReturnVersion)
    throw PacketError("return packet: version " + std::to_string(version) + ", expected 4");
  ReturnData d;
  d.player_num = in.u8();
  d.team_num = in.u8();
  d.fallen = in.u8();
  for (float& v : d.pose) v = in.f32();
  d.ball_age = in.f32();
  for (float& v : d.ball) v = in.f32();
  if (d.player_num < 1 || d.player_num > gc::kMaxPlayers)
    throw PacketError("return packet: playerNum " + std::to_string(d.player_num) + " not in 1..20");
  if (d.fallen > 1)
    throw PacketError("return packet: fallen " + std::to_string(d.fallen) + " not 0 or 1");
  for (float v : {d.pose[0], d.pose[1], d.pose[2], d.ball_age, d.ball[0], d.ball[1]})
    if (std::isnan(v)) throw PacketError("return packet: NaN field");
  return d;
}

UdpSender::UdpSender(const std::string& address, uint16_t port) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd_ < 0) throw std::runtime_error("UDP: socket: " + std::string(std::strerror(errno)));
  const int yes = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_BROADCAST, &yes, sizeof yes);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &a.sin_addr) != 1) {
    ::close(fd_);
    throw std::runtime_error("UDP: '" + address + "' is not an IPv4 address");
  }
  static_assert(sizeof a <= sizeof address_);
  std::memcpy(address_.data(), &a, sizeof a);
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpSender::send(std::span<const uint8_t> bytes) {
  ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(address_.data()),
           sizeof(sockaddr_in));
}

UdpReceiver::UdpReceiver(uint16_t port, const std::string& bind_address,
                         const std::string& device) {
  fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd_ < 0) throw std::runtime_error("UDP: socket: " + std::string(std::strerror(errno)));
  // A well-known port (the GameController's 3838, a team port) is shared by
  // every program on the host that listens to it. A port the system picks
  // (0) is this socket's alone: shared, a later socket with SO_REUSEADDR
  // (a DDS participant's) could take it and receive its packets.
  if (port != 0) {
    const int yes = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  }
  if (!device.empty() && ::setsockopt(fd_, SOL_SOCKET, SO_BINDTODEVICE, device.c_str(),
                                      static_cast<socklen_t>(device.size())) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("UDP: cannot bind port " + std::to_string(port) + " to " + device +
                             ": " + why);
  }
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  ::inet_pton(AF_INET, bind_address.c_str(), &a.sin_addr);
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("UDP: cannot bind port " + std::to_string(port) + ": " + why);
  }
  socklen_t len = sizeof a;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

size_t UdpReceiver::receive(std::span<uint8_t> buffer, double timeout_seconds,
                            std::string* source) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout_seconds * 1000)) <= 0) return 0;
  sockaddr_in from{};
  socklen_t from_size = sizeof from;
  const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC,
                               reinterpret_cast<sockaddr*>(&from), &from_size);
  if (source && n > 0) {
    char text[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &from.sin_addr, text, sizeof text);
    *source = text;
  }
  // An oversized datagram is cut to the buffer: its size still tells it is not a packet.
  return n > 0 ? std::min(static_cast<size_t>(n), buffer.size()) : 0;
}

}  // namespace simsoccer::referee

#include "simsoccer/lola/sensor_packet.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string_view>

namespace simsoccer::lola {

RobotIdentity defaultIdentity(int team_number, int player) {
  char body[32];
  std::snprintf(body, sizeof body, "SIMSOCCERT%03uP%02u0000",
                static_cast<unsigned>(team_number) % 1000u, static_cast<unsigned>(player) % 100u);
  RobotIdentity id;
  id.body_id = body;
  return id;
}

namespace {
void checkString(const std::string& s, std::size_t length, const char* field, bool version) {
  if (s.size() != length)
    throw std::invalid_argument(std::string("lola: ") + field + " '" + s + "' must be " +
                                std::to_string(length) + " characters (is " +
                                std::to_string(s.size()) + ")");
  for (char c : s)
    if (c < 0x20 || c > 0x7e)
      throw std::invalid_argument(std::string("lola: ") + field + " must be printable ASCII");
  if (version && (s[0] < '0' || s[0] > '9'))
    throw std::invalid_argument(std::string("lola: ") + field + " '" + s +
                                "' must start with a digit (team code parses it)");
}
}  // namespace

void checkIdentity(const RobotIdentity& id) {
  checkString(id.body_id, kIdChars, "body_id", false);
  checkString(id.body_version, kVersionChars, "body_version", true);
  checkString(id.head_id, kIdChars, "head_id", false);
  checkString(id.head_version, kVersionChars, "head_version", true);
}

BatteryModel::BatteryModel(double initial_charge, double capacity_ah, double idle_current_a)
    : capacity_coulomb_(capacity_ah * 3600.0),
      idle_current_a_(idle_current_a),
      charge_(std::clamp(initial_charge, 0.0, 1.0)) {
  reading_.charge = static_cast<float>(charge_);
  reading_.current = static_cast<float>(-idle_current_a_);
}

void BatteryModel::update(const world::SensorFrame& frame, double dt) {
  // The motors draw from the battery through their drivers; the sum of
  // their currents plus the head's computer is what the battery gives.
  double drawn = idle_current_a_;
  for (float a : frame.current) drawn += std::abs(static_cast<double>(a));
  charge_ = std::max(0.0, charge_ - drawn * dt / capacity_coulomb_);
  reading_.charge = static_cast<float>(charge_);
  reading_.current = static_cast<float>(-drawn);
}

SensorValues fromFrame(const world::SensorFrame& f, const Battery& battery) {
  static_assert(world::kActuators == kJoints);
  SensorValues v;
  v.position = f.position;
  v.stiffness = f.stiffness;
  v.current = f.current;
  v.temperature = f.temperature;
  for (std::size_t j = 0; j < kJoints; ++j) v.status[j] = std::min<uint8_t>(f.status[j], 3);
  // LoLA's raw accelerometer reads minus the specific force (about -9.81 on
  // z upright; B-Human negates all three axes on reading it). The frame
  // holds the specific force.
  for (int k = 0; k < 3; ++k) v.accelerometer[k] = -f.accelerometer[k];
  v.gyroscope = f.gyroscope;
  v.angles = {f.angles[0], f.angles[1]};
  v.fsr = f.fsr_kg;
  for (std::size_t t = 0; t < world::kTouchSensors; ++t) v.touch[t] = f.touch[t] ? 1.0f : 0.0f;
  v.sonar = f.sonar;
  v.battery = battery;
  return v;
}

namespace {
// Writes MessagePack with the exact types LoLA uses.
class Writer {
 public:
  explicit Writer(SensorPacket& out) : out_(out) {}
  void byte(uint8_t b) {
    if (n_ >= out_.size()) throw std::logic_error("lola: sensor packet over 896 bytes");
    out_[n_++] = b;
  }
  void mapHeader(std::size_t n) { byte(static_cast<uint8_t>(0x80 | n)); }  // fixmap
  void arrayHeader(std::size_t n) {
    if (n < 16) {
      byte(static_cast<uint8_t>(0x90 | n));  // fixarray
    } else {
      byte(0xdc);  // array16
      byte(static_cast<uint8_t>(n >> 8));
      byte(static_cast<uint8_t>(n & 0xff));
    }
  }
  void str(std::string_view s) {  // fixstr (every string of the packet is < 32 bytes)
    byte(static_cast<uint8_t>(0xa0 | s.size()));
    for (char c : s) byte(static_cast<uint8_t>(c));
  }
  void f32(float x) {
    const uint32_t bits = std::bit_cast<uint32_t>(x);
    byte(0xca);
    for (int shift = 24; shift >= 0; shift -= 8) byte(static_cast<uint8_t>(bits >> shift));
  }
  template <std::size_t N>
  void floats(std::string_view key, const std::array<float, N>& a) {
    str(key);
    arrayHeader(N);
    for (float x : a) f32(x);
  }
  std::size_t size() const { return n_; }

 private:
  SensorPacket& out_;
  std::size_t n_ = 0;
};
}  // namespace

SensorPacket encodeSensorPacket(const SensorValues& v, const RobotIdentity& id) {
  checkIdentity(id);
  SensorPacket packet{};
  Writer w(packet);
  w.mapHeader(13);
  w.str("RobotConfig");
  w.arrayHeader(4);
  w.str(id.body_id);
  w.str(id.body_version);
  w.str(id.head_id);
  w.str(id.head_version);
  w.floats("Accelerometer", v.accelerometer);
  w.floats("Angles", v.angles);
  w.floats("Battery", std::array<float, 4>{v.battery.charge, v.battery.status, v.battery.current,
                                           v.battery.temperature});
  w.floats("Current", v.current);
  w.floats("FSR", v.fsr);
  w.floats("Gyroscope", v.gyroscope);
  w.floats("Position", v.position);
  w.floats("Sonar", v.sonar);
  w.floats("Stiffness", v.stiffness);
  w.floats("Temperature", v.temperature);
  w.floats("Touch", v.touch);
  w.str("Status");
  w.arrayHeader(kJoints);
  for (uint8_t s : v.status) w.byte(s);  // positive fixint (0..3 < 0x80)
  if (w.size() != kSensorPacketBytes)
    throw std::logic_error("lola: sensor packet is " + std::to_string(w.size()) + " bytes, not 896");
  return packet;
}

}  // namespace simsoccer::lola

#include "simsoccer/world/match_log.hpp"

#include <zlib.h>

#include <cstring>
#include <sstream>
#include <stdexcept>

namespace simsoccer::world {
namespace {

constexpr char kMagic[8] = {'S', 'S', 'M', 'L', 'O', 'G', 0, 0};
constexpr int kFramesPerBlock = 100;

struct Out {
  std::vector<uint8_t>& b;
  template <class T>
  void raw(const T& v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
  }
  void i16(double v, double scale) {
    raw(static_cast<int16_t>(std::max(-32767.0, std::min(32767.0, std::round(v / scale)))));
  }
  void str(const std::string& s) {
    raw(static_cast<uint16_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
  }
};

struct In {
  const std::vector<uint8_t>& b;
  size_t& p;
  template <class T>
  T raw() {
    if (p + sizeof(T) > b.size()) throw std::runtime_error("frame runs past its block");
    T v;
    std::memcpy(&v, b.data() + p, sizeof(T));
    p += sizeof(T);
    return v;
  }
  double i16(double scale) { return raw<int16_t>() * scale; }
  std::string str() {
    const auto n = raw<uint16_t>();
    if (p + n > b.size()) throw std::runtime_error("string runs past its block");
    std::string s(reinterpret_cast<const char*>(b.data() + p), n);
    p += n;
    return s;
  }
};

void putPose(Out& o, const Pose& pose) {
  for (int k = 0; k < 3; ++k) o.raw(static_cast<float>(pose.translation()[k]));
  const Eigen::Quaterniond q(pose.linear());
  for (double v : {q.x(), q.y(), q.z(), q.w()}) o.i16(v, 1.0 / 32767.0);
}
Pose getPose(In& in) {
  Pose pose = Pose::Identity();
  for (int k = 0; k < 3; ++k) pose.translation()[k] = in.raw<float>();
  double q[4];
  for (double& v : q) v = in.i16(1.0 / 32767.0);
  pose.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  return pose;
}

}  // namespace

MatchLogWriter::MatchLogWriter(const std::filesystem::path& file, const MatchLogHeader& header)
    : out_(file, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(file.string() + ": cannot write the match log");
  std::ostringstream h;
  for (const auto& [k, v] : header.values) h << k << '=' << v << '\n';
  for (const auto& r : header.robots)
    h << "robot=" << r.team << ',' << r.number << ',' << r.joints << '\n';
  const std::string text = h.str();
  out_.write(kMagic, 8);
  const uint32_t version = kMatchLogVersion, length = static_cast<uint32_t>(text.size());
  out_.write(reinterpret_cast<const char*>(&version), 4);
  out_.write(reinterpret_cast<const char*>(&length), 4);
  out_.write(text.data(), static_cast<std::streamsize>(text.size()));
  bytes_ = 16 + text.size();
}

MatchLogWriter::~MatchLogWriter() {
  try {
    flush();
  } catch (...) {
  }
}

void MatchLogWriter::write(const LogFrame& f) {
  Out o{block_};
  o.raw(f.tick);
  o.raw(f.time);
  o.raw(f.state_hash);
  o.raw(static_cast<uint16_t>(f.game.size()));
  block_.insert(block_.end(), f.game.begin(), f.game.end());
  putPose(o, f.ball);
  o.raw(static_cast<uint16_t>(f.robots.size()));
  for (const LoggedRobot& r : f.robots) {
    putPose(o, r.torso);
    o.raw(static_cast<uint16_t>(r.joints.size()));
    for (double q : r.joints) o.i16(q, kCommandResolution);
    for (double q : r.command_position) o.i16(q, kCommandResolution);
    o.raw(static_cast<uint8_t>(r.commanded));
    for (double s : r.command_stiffness) o.raw(static_cast<uint8_t>(std::lround(s * 255.0)));
    o.raw(static_cast<uint8_t>(r.leds.has_value()));
    if (r.leds)
      for (uint8_t v : *r.leds) o.raw(v);
  }
  o.raw(static_cast<uint16_t>(f.events.size()));
  for (const LogEvent& e : f.events) {
    o.raw(e.time);
    o.str(e.type);
    o.raw(static_cast<int8_t>(e.team));
    o.raw(static_cast<uint8_t>(e.player));
    o.str(e.detail);
  }
  ++frames_;
  if (++in_block_ >= kFramesPerBlock) flush();
}

void MatchLogWriter::flush() {
  if (block_.empty()) return;
  uLongf packed = compressBound(static_cast<uLong>(block_.size()));
  std::vector<uint8_t> z(packed);
  if (compress2(z.data(), &packed, block_.data(), static_cast<uLong>(block_.size()), 6) != Z_OK)
    throw std::runtime_error("match log: compression failed");
  const uint32_t raw = static_cast<uint32_t>(block_.size()), zl = static_cast<uint32_t>(packed);
  out_.write(reinterpret_cast<const char*>(&raw), 4);
  out_.write(reinterpret_cast<const char*>(&zl), 4);
  out_.write(reinterpret_cast<const char*>(z.data()), packed);
  out_.flush();
  bytes_ += 8 + packed;
  block_.clear();
  in_block_ = 0;
}

MatchLogReader::MatchLogReader(const std::filesystem::path& file)
    : file_(file), in_(file, std::ios::binary) {
  auto fail = [&](const std::string& why) { throw std::runtime_error(file.string() + ": " + why); };
  if (!in_) fail("cannot open the match log");
  // Lengths are checked against the file's size; a pipe has none (unbounded).
  std::error_code ec;
  file_size_ = std::filesystem::is_regular_file(file, ec) ? std::filesystem::file_size(file, ec)
                                                          : UINT64_MAX;
  if (ec) file_size_ = UINT64_MAX;
  char magic[8];
  uint32_t version = 0, length = 0;
  if (!in_.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) fail("not a simsoccer match log");
  in_.read(reinterpret_cast<char*>(&version), 4);
  in_.read(reinterpret_cast<char*>(&length), 4);
  if (!in_) fail("truncated header");
  if (version != kMatchLogVersion)
    fail("format version " + std::to_string(version) + ", this build reads " +
         std::to_string(kMatchLogVersion));
  // Lengths come from the file: none may claim more than the file holds.
  if (file_size_ != UINT64_MAX && 16ull + length > file_size_)
    fail("the header claims " + std::to_string(length) + " bytes, the file has " +
         std::to_string(file_size_ - 16) + " after its first 16");
  std::string text(length, '\0');
  if (!in_.read(text.data(), length)) fail("truncated header");
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string k = line.substr(0, eq), v = line.substr(eq + 1);
    if (k == "robot") {
      LogRobotInfo r;
      if (std::sscanf(v.c_str(), "%d,%d,%d", &r.team, &r.number, &r.joints) != 3)
        fail("bad robot line '" + line + "'");
      header_.robots.push_back(r);
    } else {
      header_.values[k] = v;
    }
  }
}

bool MatchLogReader::readBlock() {
  const auto at = static_cast<uint64_t>(in_.tellg());
  uint32_t raw = 0, packed = 0;
  if (!in_.read(reinterpret_cast<char*>(&raw), 4)) {
    if (in_.gcount() != 0) truncated_at_ = at;  // a few bytes of a block header: cut
    return false;                              // the end
  }
  const auto cut = [&] {
    truncated_at_ = at;  // the writer was stopped inside this block: what follows is lost
    return false;
  };
  if (!in_.read(reinterpret_cast<char*>(&packed), 4)) return cut();
  // A block's lengths come from the file: the packed bytes must be in it, and
  // zlib inflates at most about 1032 to 1 (a corrupt length fails here, not
  // in an allocation of gigabytes).
  if (file_size_ != UINT64_MAX && at + 8 + packed > file_size_) {
    std::error_code ec;  // a log still being written has grown since it was opened
    const auto now = std::filesystem::file_size(file_, ec);
    if (ec || at + 8 + packed > now) return cut();
    file_size_ = now;
  }
  if (raw > 1032ull * packed + 1024)
    throw std::runtime_error(file_.string() + ": the block at byte " + std::to_string(at) +
                             " claims " + std::to_string(raw) + " bytes from " +
                             std::to_string(packed) + " packed: corrupt");
  std::vector<uint8_t> z(packed);
  if (!in_.read(reinterpret_cast<char*>(z.data()), packed)) return cut();
  block_.assign(raw, 0);
  uLongf out = raw;
  if (uncompress(block_.data(), &out, z.data(), packed) != Z_OK || out != raw)
    throw std::runtime_error(file_.string() + ": the block at byte " + std::to_string(at) +
                             " is corrupt");
  pos_ = 0;
  return true;
}

bool MatchLogReader::next(LogFrame& f) {
  if (pos_ >= block_.size() && !readBlock()) return false;
  try {
    return readFrame(f);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(file_.string() + ": a corrupt frame (" + e.what() + ")");
  }
}

bool MatchLogReader::readFrame(LogFrame& f) {
  In in{block_, pos_};
  f = LogFrame{};
  f.tick = in.raw<uint64_t>();
  f.time = in.raw<double>();
  f.state_hash = in.raw<uint64_t>();
  const auto g = in.raw<uint16_t>();
  if (pos_ + g > block_.size()) throw std::runtime_error("game packet runs past its block");
  f.game.assign(block_.begin() + static_cast<long>(pos_),
                block_.begin() + static_cast<long>(pos_ + g));
  pos_ += g;
  f.ball = getPose(in);
  const auto n = in.raw<uint16_t>();
  f.robots.resize(n);
  for (LoggedRobot& r : f.robots) {
    r.torso = getPose(in);
    r.joints.resize(in.raw<uint16_t>());
    for (double& q : r.joints) q = in.i16(kCommandResolution);
    for (double& q : r.command_position) q = in.i16(kCommandResolution);
    r.commanded = in.raw<uint8_t>() != 0;
    for (double& s : r.command_stiffness) s = in.raw<uint8_t>() / 255.0;
    r.leds.reset();
    if (in.raw<uint8_t>() != 0) {
      std::array<uint8_t, 9> leds{};
      for (uint8_t& v : leds) v = in.raw<uint8_t>();
      r.leds = leds;
    }
  }
  const auto events = in.raw<uint16_t>();
  for (int i = 0; i < events; ++i) {
    LogEvent e;
    e.time = in.raw<double>();
    e.type = in.str();
    e.team = in.raw<int8_t>();
    e.player = in.raw<uint8_t>();
    e.detail = in.str();
    f.events.push_back(std::move(e));
  }
  return true;
}

LogFrame captureFrame(const World& world, uint64_t tick,
                      const std::vector<std::array<double, 25>>& positions,
                      const std::vector<std::array<double, 25>>& stiffness,
                      const std::vector<bool>& commanded) {
  LogFrame f;
  f.tick = tick;
  f.time = world.time();
  f.ball = world.ballState().pose;
  f.state_hash = world.stateHash();
  for (RobotId r = 0; r < world.robotCount(); ++r) {
    LoggedRobot lr;
    lr.torso = world.torsoPose(r);
    const int n = static_cast<int>(world.robot(r).model->body->joints.size());
    for (int j = 0; j < n; ++j) lr.joints.push_back(world.jointPosition(r, j));
    if (r < positions.size()) lr.command_position = positions[r];
    if (r < stiffness.size()) lr.command_stiffness = stiffness[r];
    lr.commanded = r < commanded.size() && commanded[r];
    f.robots.push_back(std::move(lr));
  }
  return f;
}

void applyFrame(World& world, const LogFrame& f) {
  for (RobotId r = 0; r < world.robotCount() && r < f.robots.size(); ++r)
    world.physics().resetArticulation(world.robot(r).body, f.robots[r].torso, f.robots[r].joints);
  engine::RigidBodyState b;
  b.pose = f.ball;
  world.setBallState(b);
}

}  // namespace simsoccer::world

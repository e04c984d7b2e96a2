#include "simsoccer/engine/config.hpp"

#include <yaml-cpp/eventhandler.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

namespace simsoccer::engine {

ConfigError::ConfigError(std::string file, std::string key, std::string reason)
    : std::runtime_error(file + ": " + (key.empty() ? std::string("(document)") : key) + ": " +
                         reason),
      file_(std::move(file)),
      key_(std::move(key)),
      reason_(std::move(reason)) {}

namespace {
// Keys must be strings, and no mapping may have a key twice (YAML forbids it;
// yaml-cpp keeps the first silently). Aliases can make the document a loop
// or blow it up exponentially: depth and node count are bounded.
void checkKeys(const YAML::Node& node, const std::string& file, const std::string& path,
               int depth, long& budget) {
  if (depth > 64 || --budget < 0)
    throw ConfigError(file, path,
                      "nested deeper than 64 or more than 100000 nodes (an alias loop?)");
  const auto where = [](const YAML::Node& n) {
    return " (line " + std::to_string(n.Mark().line + 1) + ")";
  };
  if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar())
        throw ConfigError(file, path, "a key that is not a string" + where(kv.first));
      const std::string key = kv.first.Scalar();
      if (!seen.insert(key).second)
        throw ConfigError(file, path.empty() ? key : path + "." + key,
                          "the key appears twice" + where(kv.first));
      checkKeys(kv.second, file, path.empty() ? key : path + "." + key, depth + 1, budget);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      checkKeys(node[i], file, path + "[" + std::to_string(i) + "]", depth + 1, budget);
  }
}
// Counts a YAML document's nodes but nulls (an empty document after a trailing --- is one).
class NodeCounter : public YAML::EventHandler {
 public:
  int nodes = 0;
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { ++nodes; }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {
    ++nodes;
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    ++nodes;
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    ++nodes;
  }
  void OnMapEnd() override {}
};

// A document after the first with content would be read by nobody: refused rather than
// ignored. At most 64 documents are parsed: yaml-cpp 0.7's LoadAll loops for ever on some
// malformed input (found by fuzz_configs and fuzz_agent_inputs).
bool secondDocumentHasContent(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  YAML::Parser parser(in);
  NodeCounter first;
  if (!parser.HandleNextDocument(first)) return false;
  for (int documents = 1; documents < 64; ++documents) {
    NodeCounter next;
    if (!parser.HandleNextDocument(next)) return false;
    if (next.nodes > 0) return true;
  }
  return false;
}

}  // namespace

ConfigNode ConfigNode::loadFile(const std::filesystem::path& file) {
  const std::string name = file.string();
  if (!std::filesystem::exists(file)) throw ConfigError(name, "", "file not found");
  if (!std::filesystem::is_regular_file(file)) throw ConfigError(name, "", "not a regular file");
  try {
    YAML::Node root = YAML::LoadFile(name);
    if (secondDocumentHasContent(file))
      throw ConfigError(name, "",
                        "holds a second YAML document (after a --- line), which nothing reads; a "
                        "config file is one document");
    if (!root.IsMap()) throw ConfigError(name, "", "expected a mapping at the top level");
    long budget = 100000;
    checkKeys(root, name, "", 0, budget);
    return ConfigNode(root, name, "");
  } catch (const YAML::BadFile&) {
    throw ConfigError(name, "", "cannot be read");
  } catch (const YAML::ParserException& e) {
    throw ConfigError(name, "",
                      "YAML syntax error at line " + std::to_string(e.mark.line + 1) + ", column " +
                          std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

ConfigNode::ConfigNode(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string ConfigNode::childPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void ConfigNode::fail(const std::string& reason) const {
  throw ConfigError(file_, path_, reason);
}
void ConfigNode::failKey(const std::string& key, const std::string& reason) const {
  throw ConfigError(file_, childPath(key), reason);
}

bool ConfigNode::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

ConfigNode ConfigNode::operator[](const std::string& key) const {
  if (!node_.IsMap()) fail("expected a mapping with key '" + key + "'");
  const YAML::Node child = node_[key];
  if (!child.IsDefined() || child.IsNull()) failKey(key, "missing required key");
  return ConfigNode(child, file_, childPath(key));
}

std::optional<ConfigNode> ConfigNode::optional(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return ConfigNode(node_[key], file_, childPath(key));
}

void ConfigNode::allowOnly(std::initializer_list<const char*> allowed) const {
  if (!node_.IsMap()) fail("expected a mapping");
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    bool ok = false;
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      failKey(key, "unknown key (allowed: " + list + ")");
    }
  }
}

std::vector<ConfigNode> ConfigNode::items() const {
  if (!node_.IsSequence()) fail("expected a list");
  std::vector<ConfigNode> out;
  for (size_t i = 0; i < node_.size(); ++i)
    out.emplace_back(node_[i], file_, path_ + "[" + std::to_string(i) + "]");
  return out;
}

std::vector<std::pair<std::string, ConfigNode>> ConfigNode::entries() const {
  if (!node_.IsMap()) fail("expected a mapping");
  std::vector<std::pair<std::string, ConfigNode>> out;
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    out.emplace_back(key, ConfigNode(kv.second, file_, childPath(key)));
  }
  return out;
}

double ConfigNode::number() const {
  if (!node_.IsScalar()) fail("expected a number");
  try {
    const double v = node_.as<double>();
    if (!std::isfinite(v)) fail("expected a finite number, got '" + node_.Scalar() + "'");
    return v;
  } catch (const YAML::BadConversion&) {
    fail("expected a number, got '" + node_.Scalar() + "'");
  }
}

double ConfigNode::positive() const {
  const double v = number();
  if (!(v > 0.0)) fail("must be > 0, got " + node_.Scalar());
  // A denormal is > 0 but no physical size or time: 1e-320 m is a typo.
  if (!std::isnormal(v)) fail("must be a normal positive number, got " + node_.Scalar());
  return v;
}

double ConfigNode::nonNegative() const {
  const double v = number();
  if (v < 0.0) fail("must be >= 0, got " + node_.Scalar());
  return v;
}

int ConfigNode::integer() const {
  if (!node_.IsScalar()) fail("expected an integer");
  try {
    return node_.as<int>();
  } catch (const YAML::BadConversion&) {
    fail("expected an integer, got '" + node_.Scalar() + "'");
  }
}

bool ConfigNode::boolean() const {
  if (!node_.IsScalar()) fail("expected true or false");
  try {
    return node_.as<bool>();
  } catch (const YAML::BadConversion&) {
    fail("expected true or false, got '" + node_.Scalar() + "'");
  }
}

std::string ConfigNode::string() const {
  if (!node_.IsScalar()) fail("expected a string");
  return node_.Scalar();
}

std::vector<double> ConfigNode::numbers() const {
  std::vector<double> out;
  for (const ConfigNode& item : items()) out.push_back(item.number());
  return out;
}

std::vector<double> ConfigNode::numbers(size_t count) const {
  if (!node_.IsSequence() || node_.size() != count)
    fail("expected a list of " + std::to_string(count) + " numbers");
  return numbers();
}

Vec3 ConfigNode::vec3() const {
  const auto v = numbers(3);
  return Vec3(v[0], v[1], v[2]);
}

double ConfigNode::number(const std::string& key, double fallback) const {
  return has(key) ? (*this)[key].number() : fallback;
}
int ConfigNode::integer(const std::string& key, int fallback) const {
  return has(key) ? (*this)[key].integer() : fallback;
}
bool ConfigNode::boolean(const std::string& key, bool fallback) const {
  return has(key) ? (*this)[key].boolean() : fallback;
}

std::string formatNumber(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

std::filesystem::path resolveBeside(const std::string& base_file, const std::string& relative) {
  const std::filesystem::path rel(relative);
  if (rel.is_absolute()) return rel;
  return std::filesystem::path(base_file).parent_path() / rel;
}

Pose readPose(const ConfigNode& node) {
  Pose pose = Pose::Identity();
  if (auto p = node.optional("position")) pose.translation() = p->vec3();
  const bool has_rpy = node.has("rpy");
  const bool has_axis = node.has("axis");
  if (has_rpy && has_axis) node.fail("give either 'rpy' or 'axis', not both");
  if (has_rpy) {
    const Vec3 rpy = node["rpy"].vec3();
    pose.linear() =
        (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
         Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
            .toRotationMatrix();
  } else if (has_axis) {
    const Vec3 axis = node["axis"].vec3();
    if (axis.norm() < 1e-9) node.failKey("axis", "must not be the zero vector");
    pose.linear() = Quat::FromTwoVectors(Vec3::UnitZ(), axis.normalized()).toRotationMatrix();
  }
  return pose;
}

Shape readShape(const ConfigNode& node) {
  node.allowOnly({"sphere", "box", "capsule", "cylinder", "position", "rpy", "axis"});
  Shape s;
  int kinds = 0;
  if (auto n = node.optional("sphere")) {
    ++kinds;
    n->allowOnly({"radius"});
    s.type = ShapeType::Sphere;
    s.radius = (*n)["radius"].positive();
  }
  if (auto n = node.optional("box")) {
    ++kinds;
    n->allowOnly({"size"});
    s.type = ShapeType::Box;
    s.extents = (*n)["size"].vec3();
    if (s.extents.minCoeff() <= 0.0) n->failKey("size", "every side must be > 0");
  }
  for (const char* kind : {"capsule", "cylinder"}) {
    if (auto n = node.optional(kind)) {
      ++kinds;
      n->allowOnly({"radius", "length"});
      s.type = std::string(kind) == "capsule" ? ShapeType::Capsule : ShapeType::Cylinder;
      s.radius = (*n)["radius"].positive();
      s.length = (*n)["length"].positive();
      if (s.type == ShapeType::Capsule && s.length < 2.0 * s.radius)
        n->failKey("length", "a capsule's length includes its caps: must be >= 2 * radius");
    }
  }
  if (kinds != 1) node.fail("expected exactly one of sphere, box, capsule, cylinder");
  s.pose = readPose(node);
  return s;
}

Material readMaterial(const ConfigNode& node, const Material& defaults) {
  node.allowOnly({"friction", "rolling_friction", "spinning_friction", "restitution"});
  Material m = defaults;
  if (auto n = node.optional("friction")) m.friction = n->nonNegative();
  if (auto n = node.optional("rolling_friction")) m.rolling_friction = n->nonNegative();
  if (auto n = node.optional("spinning_friction")) m.spinning_friction = n->nonNegative();
  if (auto n = node.optional("restitution")) {
    m.restitution = n->nonNegative();
    if (m.restitution > 1.0) n->fail("must be in [0, 1]");
  }
  return m;
}

}  // namespace simsoccer::engine

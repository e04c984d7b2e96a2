// Reading YAML model and scenario files with errors that name the file, the
// key path and the reason. Every component's loader uses this: a bad file
// stops at load, never with a silent default for a required value.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::engine {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string file, std::string key, std::string reason);
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_, key_, reason_;
};

// A node of a YAML document that knows where it came from.
class ConfigNode {
 public:
  static ConfigNode loadFile(const std::filesystem::path& file);
  ConfigNode(YAML::Node node, std::string file, std::string path);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const YAML::Node& raw() const { return node_; }

  bool has(const std::string& key) const;
  ConfigNode operator[](const std::string& key) const;  // required: missing -> error
  std::optional<ConfigNode> optional(const std::string& key) const;
  // Map keys that are not in `allowed` are errors (catches typos).
  void allowOnly(std::initializer_list<const char*> allowed) const;

  std::vector<ConfigNode> items() const;                            // sequence
  std::vector<std::pair<std::string, ConfigNode>> entries() const;  // map, file order

  double number() const;
  double positive() const;     // > 0
  double nonNegative() const;  // >= 0
  int integer() const;
  bool boolean() const;
  std::string string() const;
  std::vector<double> numbers() const;              // sequence of numbers
  std::vector<double> numbers(size_t count) const;  // exactly `count`
  Vec3 vec3() const;

  // Typed getters with a default for optional keys.
  double number(const std::string& key, double fallback) const;
  int integer(const std::string& key, int fallback) const;
  bool boolean(const std::string& key, bool fallback) const;

  [[noreturn]] void fail(const std::string& reason) const;
  [[noreturn]] void failKey(const std::string& key, const std::string& reason) const;
  std::string childPath(const std::string& key) const;

 private:
  YAML::Node node_;
  std::string file_;
  std::string path_;
};

// A number as it reads in a message: 0.005, not 0.005000.
std::string formatNumber(double value);

// Resolves `relative` against the folder of the file `base` was read from.
std::filesystem::path resolveBeside(const std::string& base_file, const std::string& relative);

// A collision primitive: {sphere|box|capsule|cylinder: {...}, position, rpy|axis}.
Shape readShape(const ConfigNode& node);
// position (m) and orientation: either rpy (rad, roll-pitch-yaw, fixed axes
// x then y then z) or an axis that the shape's z axis is turned onto.
Pose readPose(const ConfigNode& node);
Material readMaterial(const ConfigNode& node, const Material& defaults);

}  // namespace simsoccer::engine

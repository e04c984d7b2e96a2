// Option parsing for the command-line programs: --key value and --flag after the subcommand
// words, each value checked with a usage error that names the option.
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "cli.hpp"

namespace simsoccer::apps {

Options::Options(int argc, char** argv, int first, const std::vector<std::string>& flags,
                 const std::vector<std::string>& valued) {
  auto in = [](const std::vector<std::string>& v, const std::string& s) {
    for (const auto& x : v)
      if (x == s) return true;
    return false;
  };
  for (int i = first; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) == 0) {
      const std::string name = a.substr(2);
      if (in(flags, name)) {
        flags_[name] = true;
      } else if (in(valued, name)) {
        // A value never starts with "--": there it is the next option, and this one's value
        // was left out.
        if (i + 1 >= argc || std::string(argv[i + 1]).rfind("--", 0) == 0)
          throw UsageError("option --" + name + " needs a value");
        values_[name] = argv[++i];
      } else {
        throw UsageError("unknown option " + a);
      }
    } else {
      positional_.push_back(a);
    }
  }
  // Tables and plots are written after the run: a path they cannot go to is refused before it.
  for (const char* name : {"csv", "png"}) checkWritable(name);
}

void Options::checkWritable(const std::string& name) const {
  if (!has(name)) return;
  const std::filesystem::path file = values_.at(name);
  const std::string what = std::string("--") + name + " " + file.string() + ": ";
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw UsageError(what + "is a folder");
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
  if (!std::filesystem::is_directory(folder, ec))
    throw UsageError(what + "no such folder " + folder.string());
  const bool exists = std::filesystem::exists(file, ec);
  if (exists ? ::access(file.c_str(), W_OK) != 0 : ::access(folder.c_str(), W_OK) != 0)
    throw UsageError(what + "not writable");
}

bool Options::help(const char* text) const {
  if (!flag("help")) return false;
  std::fputs(text, stdout);
  return true;
}

void Options::noPositional() const {
  if (!positional_.empty()) throw UsageError("unexpected argument '" + positional_[0] + "'");
}

std::string Options::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

double Options::number(const std::string& name, double fallback) const {
  if (!has(name)) return fallback;
  const std::string v = values_.at(name);
  try {
    size_t used = 0;
    const double d = std::stod(v, &used);
    if (used != v.size() || !std::isfinite(d)) throw std::invalid_argument(v);
    return d;
  } catch (const std::exception&) {
    throw UsageError("--" + name + ": expected a number, got '" + v + "'");
  }
}

int Options::wholeNumber(const std::string& name, int fallback, int lo, int hi) const {
  if (!has(name)) return fallback;
  const double v = number(name, fallback);
  if (v < lo || v > hi || v != std::floor(v))
    throw UsageError("--" + name + " must be a whole number from " + std::to_string(lo) + " to " +
                     std::to_string(hi));
  return static_cast<int>(v);
}

double Options::positive(const std::string& name, double fallback) const {
  const double v = number(name, fallback);
  if (has(name) && !(v > 0)) throw UsageError("--" + name + " must be > 0");
  return v;
}

double Options::nonNegative(const std::string& name, double fallback) const {
  const double v = number(name, fallback);
  if (has(name) && v < 0) throw UsageError("--" + name + " must be >= 0");
  return v;
}

uint64_t Options::seed(const std::string& name, uint64_t fallback) const {
  if (!has(name)) return fallback;
  const std::string v = values_.at(name);
  uint64_t seed = 0;
  const auto [end, error] = std::from_chars(v.data(), v.data() + v.size(), seed);
  if (v.empty() || error != std::errc() || end != v.data() + v.size())
    throw UsageError("--" + name +
                     ": expected a whole number from 0 to 18446744073709551615, got '" + v + "'");
  return seed;
}

uint32_t Options::domain(const std::string& name, uint32_t fallback) const {
  return static_cast<uint32_t>(wholeNumber(name, static_cast<int>(fallback), 0, 232));
}

namespace {

// A comma-separated list of values, each read by `parse` (which throws on a
// bad one), or a usage error naming the option and what was expected.
template <class T, class Parse>
std::vector<T> parseList(const std::string& name, const std::string& text, const char* expected,
                         Parse parse) {
  std::vector<T> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      out.push_back(parse(item));
    } catch (const std::exception&) {
      throw UsageError("--" + name + ": expected " + expected + " separated by commas, got '" +
                       text + "'");
    }
  }
  if (out.empty()) throw UsageError("--" + name + ": empty list");
  return out;
}

}  // namespace

std::vector<int> Options::intList(const std::string& name, const std::vector<int>& fallback) const {
  if (!has(name)) return fallback;
  return parseList<int>(name, values_.at(name), "positive integers", [](const std::string& item) {
    size_t used = 0;
    const int v = std::stoi(item, &used);
    if (used != item.size() || v < 1) throw std::invalid_argument(item);
    return v;
  });
}

std::vector<double> Options::positiveList(const std::string& name,
                                          const std::vector<double>& fallback) const {
  if (!has(name)) return fallback;
  return parseList<double>(name, values_.at(name), "numbers > 0", [](const std::string& item) {
    size_t used = 0;
    const double v = std::stod(item, &used);
    if (used != item.size() || !(v > 0) || !std::isfinite(v)) throw std::invalid_argument(item);
    return v;
  });
}

}  // namespace simsoccer::apps

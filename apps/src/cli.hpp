// Small helpers shared by the subcommands: option parsing and tables.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace simsoccer::apps {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// --key value / --flag options after the subcommand words.
class Options {
 public:
  Options(int argc, char** argv, int first, const std::vector<std::string>& flags,
          const std::vector<std::string>& valued);
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::string get(const std::string& name, const std::string& fallback) const;
  double number(const std::string& name, double fallback) const;
  // A whole number from `lo` to `hi` (a usage error naming the option if
  // not), or `fallback` when the option is not given.
  int wholeNumber(const std::string& name, int fallback, int lo, int hi) const;
  // A number > 0 (>= 0), finite, or a usage error naming the option.
  double positive(const std::string& name, double fallback) const;
  double nonNegative(const std::string& name, double fallback) const;
  // A seed: a whole number from 0 to 2^64 - 1, written in digits.
  uint64_t seed(const std::string& name, uint64_t fallback) const;
  // A DDS domain id: 0..232 (the RTPS port mapping's range).
  uint32_t domain(const std::string& name, uint32_t fallback) const;
  std::vector<int> intList(const std::string& name, const std::vector<int>& fallback) const;
  // Finite numbers > 0 separated by commas, or a usage error naming the option.
  std::vector<double> positiveList(const std::string& name,
                                   const std::vector<double>& fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // --help given: prints `text` and returns true.
  bool help(const char* text) const;
  // Throws a UsageError if there are arguments that are not options.
  void noPositional() const;
  // Option `name`, when given, names a file this run can write (its folder exists and is
  // writable), else a UsageError. --csv and --png are checked when parsed.
  void checkWritable(const std::string& name) const;

 private:
  std::map<std::string, bool> flags_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

// A config file given on the command line, or the default one looked up in
// the working directory and then in the source tree.
std::filesystem::path findConfig(const std::string& given, const std::string& default_relative);

// Prints rows as an aligned table to stdout and optionally as CSV.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  void print(FILE* out) const;
  void writeCsv(const std::filesystem::path& file) const;  // throws on I/O error
  // What every bench ends with: the table, its legend, and the CSV when asked for.
  void finish(const std::string& legend, const std::filesystem::path& csv) const;
};

std::string fmt(double value, int decimals);

// A long run (a match, a soak) stops cleanly on SIGINT or SIGTERM, and on SIGHUP (a closed
// terminal) unless that is ignored (nohup): stopOnSignals installs the handler once,
// stopSignalled says whether one came.
void stopOnSignals();
bool stopSignalled();

// runs/PREFIX<local date-time>, where a run writes when no --out is given.
std::filesystem::path timestampedRunDir(const std::string& prefix);

int benchPhysics(int argc, char** argv, int first);
int lolaRun(int argc, char** argv, int first);
int boosterRun(int argc, char** argv, int first);
int benchSensors(int argc, char** argv, int first);
int benchNet(int argc, char** argv, int first);
int benchCameras(int argc, char** argv, int first);
int benchMotion(int argc, char** argv, int first);
int benchScaling(int argc, char** argv, int first);
int serve(int argc, char** argv, int first);
int match(int argc, char** argv, int first);
int penalty(int argc, char** argv, int first);
int replay(int argc, char** argv, int first);
int check(int argc, char** argv, int first);
int soak(int argc, char** argv, int first);
int credentials(int argc, char** argv, int first);

}  // namespace simsoccer::apps

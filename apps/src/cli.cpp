// Shared by the command-line programs: tables, config lookup, run folders, stop signals
// (the options are options.cpp).
#include "cli.hpp"

#include <signal.h>

#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>

namespace simsoccer::apps {
namespace {

volatile std::sig_atomic_t g_stop_signalled = 0;
void onStopSignal(int) {
  g_stop_signalled = 1;
}

}  // namespace

void stopOnSignals() {
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
  struct sigaction hangup {};
  if (::sigaction(SIGHUP, nullptr, &hangup) == 0 && hangup.sa_handler != SIG_IGN)
    std::signal(SIGHUP, onStopSignal);
}

bool stopSignalled() {
  return g_stop_signalled != 0;
}

std::filesystem::path timestampedRunDir(const std::string& prefix) {
  char buf[32];
  const std::time_t t = std::time(nullptr);
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&t));
  return std::filesystem::path("runs") / (prefix + buf);
}

std::filesystem::path findConfig(const std::string& given, const std::string& default_relative) {
  if (!given.empty()) return given;
  if (std::filesystem::exists(default_relative)) return default_relative;
  return std::filesystem::path(SIMSOCCER_SOURCE_DIR) / default_relative;
}

std::string fmt(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

void Table::print(FILE* out) const {
  std::vector<size_t> width(header.size());
  for (size_t c = 0; c < header.size(); ++c) {
    width[c] = header[c].size();
    for (const auto& r : rows) width[c] = std::max(width[c], r[c].size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    for (size_t c = 0; c < cells.size(); ++c)
      std::fprintf(out, "%s%*s", c ? "  " : "", static_cast<int>(width[c]), cells[c].c_str());
    std::fprintf(out, "\n");
  };
  line(header);
  for (const auto& r : rows) line(r);
  std::fflush(out);
}

void Table::writeCsv(const std::filesystem::path& file) const {
  std::ofstream f(file);
  if (!f) throw std::runtime_error(file.string() + ": cannot open for writing");
  auto line = [&](const std::vector<std::string>& cells) {
    for (size_t c = 0; c < cells.size(); ++c) f << (c ? "," : "") << cells[c];
    f << "\n";
  };
  line(header);
  for (const auto& r : rows) line(r);
  if (!f) throw std::runtime_error(file.string() + ": write failed");
}

void Table::finish(const std::string& legend, const std::filesystem::path& csv) const {
  std::printf("\n");
  print(stdout);
  std::printf("\n%s\n", legend.c_str());
  if (!csv.empty()) {
    writeCsv(csv);
    std::printf("wrote %s\n", csv.c_str());
  }
}

}  // namespace simsoccer::apps

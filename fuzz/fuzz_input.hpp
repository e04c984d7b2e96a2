// Shared by the fuzz targets: an input as a file (for the loaders, which
// read files), in this process's own scratch folder.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace simsoccer::fuzz {

// Writes the input to a file named `name` in a folder of this process's own
// and returns its path (the same path every run: the loaders see new bytes).
inline std::filesystem::path asFile(const uint8_t* data, size_t size, const std::string& name) {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("simsoccer_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace simsoccer::fuzz

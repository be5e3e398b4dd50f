// The fuzz targets' scratch folder: one per process, for the files the readers open.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "mbot/common/log.hpp"

namespace mbot::fuzz {

// A folder of this process's own (logging quieted: a rejected input is not news).
inline const std::filesystem::path& Scratch() {
  static const std::filesystem::path dir = [] {
    mbot::log::SetLevel(mbot::log::Level::kQuiet);
    const std::filesystem::path d =
        std::filesystem::temp_directory_path() / ("mbot_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes the input to `path` whole; returns the path.
inline std::string WriteFile(const std::filesystem::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

}  // namespace mbot::fuzz

// The files the viewer serves and advertises, compiled into the program (libs/viewer/embed.cmake
// writes viewer_assets.cpp from web/ and schemas/ at build time): the page needs no install, and a
// request can reach nothing but these.
#pragma once

#include <cstddef>
#include <string>

namespace mbot::viewer {

struct Asset {
  const char* path;  // "web/index.html", "schemas/Grid.json"
  const char* data;
  size_t size;
  const char* mime;
};

// The asset at `path`, or nullptr.
const Asset* FindAsset(const std::string& path);

}  // namespace mbot::viewer

#include "mbot/common/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace fs = std::filesystem;

namespace mbot {

std::string TempPathFor(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / (".tmp." + std::to_string(::getpid()) + "." + p.filename().string())).string();
}

void CommitFile(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": cannot write (" + ec.message() + ")");
  }
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string tmp = TempPathFor(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot create file");
    try {
      write(out);
    } catch (...) {
      out.close();
      std::remove(tmp.c_str());
      throw;
    }
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": write failed (disk full?)");
    }
  }
  CommitFile(tmp, path);
}

AtomicFileWriter::AtomicFileWriter(std::string path)
    : path_(std::move(path)), tmp_(TempPathFor(path_)), out_(tmp_, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(path_ + ": cannot create file");
}

AtomicFileWriter::~AtomicFileWriter() {
  if (committed_) return;
  out_.close();
  std::remove(tmp_.c_str());
}

void AtomicFileWriter::Commit() {
  if (committed_) return;
  out_.flush();
  const bool good = static_cast<bool>(out_);
  out_.close();
  if (!good) {
    std::remove(tmp_.c_str());
    committed_ = true;  // nothing left to remove
    throw std::runtime_error(path_ + ": write failed (disk full?)");
  }
  committed_ = true;
  CommitFile(tmp_, path_);
}

int RemoveStaleTempFiles(const std::string& path) {
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string suffix = "." + p.filename().string();
  std::error_code ec;
  int removed = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // .tmp.<pid>.<file name>
    if (name.rfind(".tmp.", 0) != 0 || name.size() <= 5 + suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string pid_text = name.substr(5, name.size() - 5 - suffix.size());
    if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text.size() > 9)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;  // its writer may still run
    std::error_code rm;
    if (fs::remove(it->path(), rm)) ++removed;
  }
  return removed;
}

void EnsureDirectory(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw std::runtime_error(dir + ": cannot create output folder (" + ec.message() + ")");
  }
}

}  // namespace mbot

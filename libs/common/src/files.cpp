#include "mbot/common/files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace mbot {
namespace {

std::string Reason(int err) {
  switch (err) {
    case ENOENT:
    case ENOTDIR: return "no such file";
    case EACCES:
    case EPERM: return "permission denied";
    case EISDIR: return "is a directory, not a file";
    default: return std::strerror(err);
  }
}

}  // namespace

void RequireReadableFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error(path + ": " + Reason(errno));
  if (S_ISDIR(st.st_mode)) throw std::runtime_error(path + ": " + Reason(EISDIR));
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path + ": not a regular file");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": " + Reason(errno));
  ::close(fd);
}

}  // namespace mbot

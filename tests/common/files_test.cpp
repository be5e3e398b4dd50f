#include "mbot/common/files.hpp"

#include "mbot/common/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace mbot {
namespace {

std::string Why(const std::string& path) {
  try {
    RequireReadableFile(path);
    return "";
  } catch (const std::runtime_error& e) {
    return e.what();
  }
}

std::string Scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("mbot_files_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(RequireReadableFile, SaysWhyAFileCannotBeRead) {
  const std::string file = Scratch("ok.txt");
  std::ofstream(file) << "x";
  EXPECT_EQ(Why(file), "");
  EXPECT_EQ(Why(file + ".missing"), file + ".missing: no such file");
  EXPECT_EQ(Why(file + "/below"), file + "/below: no such file");
  const std::string dir = std::filesystem::path(file).parent_path().string();
  EXPECT_EQ(Why(dir), dir + ": is a directory, not a file");
}

// Root reads any file, so the unreadable case runs in a child that drops to user nobody.
TEST(RequireReadableFile, AnUnreadableFileIsPermissionDenied) {
  const std::string file = Scratch("secret.txt");
  std::ofstream(file) << "x";
  ASSERT_EQ(::chmod(file.c_str(), 0), 0);
  ASSERT_EQ(::chmod(std::filesystem::path(file).parent_path().c_str(), 0755), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) _exit(3);
    _exit(Why(file) == file + ": permission denied" ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_NE(WEXITSTATUS(status), 3) << "root could not drop to user nobody";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "expected '" << file << ": permission denied'";
}

// A file written a piece at a time appears whole at Commit, or not at all; what a killed writer left
// (its process gone) is cleaned up by the next one, what a live one is writing is not.
TEST(AtomicFileWriter, CommitsWholeOrLeavesNothingAndStaleTempFilesGo) {
  const std::string path = Scratch("pieces.tum");
  std::filesystem::remove(path);
  {
    AtomicFileWriter w(path);
    w.stream() << "a\n";
    EXPECT_FALSE(std::filesystem::exists(path));
  }  // not committed
  EXPECT_FALSE(std::filesystem::exists(path));
  {
    AtomicFileWriter w(path);
    w.stream() << "a\nb\n";
    w.Commit();
  }
  std::ifstream in(path);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(all, "a\nb\n");
  const std::string dir = std::filesystem::path(path).parent_path().string();
  const std::string dead = dir + "/.tmp.999999999.pieces.tum", mine = TempPathFor(path);
  std::ofstream(dead) << "left by a killed run";
  std::ofstream(mine) << "being written";
  EXPECT_EQ(RemoveStaleTempFiles(path), 1);
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(mine));
  std::filesystem::remove(mine);
}

}  // namespace
}  // namespace mbot

#include "mbot/drivers/map_io.hpp"

#include <gtest/gtest.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <functional>

#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

msgs::OccupancyGrid Fixture() {
  msgs::OccupancyGrid g(7, 5, 0.05, -1.25, 2.5);
  int v = -127;
  for (auto& c : g.cells()) {
    c = static_cast<int8_t>(v);
    v = v >= 120 ? -127 : v + 9;
  }
  g.at(0, 0) = 127;
  g.at(6, 4) = 0;
  return g;
}

TEST(MapIoTest, BotlabMapRoundTripIsLossless) {
  const auto g = Fixture();
  const auto path = test::TempPath("g.map");
  WriteBotlabMap(g, path);
  EXPECT_EQ(ReadBotlabMap(path), g);
}

TEST(MapIoTest, RosMapRoundTripIsLossless) {
  const auto g = Fixture();
  const auto path = test::TempPath("g.yaml");
  WriteRosMap(g, path);
  const auto back = ReadRosMap(path);
  EXPECT_EQ(back, g);
}

TEST(MapIoTest, RosMapFollowsMapServerThresholdsAndNegate) {
  // 2x1 image: a black (occupied) and a 205 (unknown with default thresholds) pixel.
  const auto pgm = test::TempPath("ros.pgm");
  {
    std::ofstream out(pgm, std::ios::binary);
    out << "P5\n2 1\n255\n" << char(0) << char(205);
  }
  const auto yaml = test::TempPath("ros.yaml");
  std::ofstream(yaml) << "image: ros.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\nnegate: 0\n"
                         "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  auto g = ReadRosMap(yaml);
  EXPECT_GT(g.at(0, 0), 0);
  EXPECT_EQ(g.at(1, 0), 0);
  EXPECT_DOUBLE_EQ(g.origin_x(), 1.0);
  std::ofstream(yaml) << "image: ros.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\nnegate: 1\n";
  g = ReadRosMap(yaml);
  EXPECT_LT(g.at(0, 0), 0);  // negated: black is free
}

TEST(MapIoTest, BadBotlabMapsNameFileAndLine) {
  const auto path = test::TempPath("bad.map");
  std::ofstream(path) << "0 0 3 2 0.05\n1 2 3\n4 x 6\n";
  try {
    ReadBotlabMap(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": line 3"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "0 0 -3 2 0.05\n";
  EXPECT_THROW(ReadBotlabMap(path), std::runtime_error);
}

// A header may not ask for more than kMaxMapCells, nor for more cells than the file can hold, nor
// for an absurd frame: each is an error naming the file and the field, before anything is allocated.
TEST(MapIoTest, HeadersAreBoundedBeforeAnythingIsAllocated) {
  auto error_of = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto path = test::TempPath("huge.map");
  std::ofstream(path) << "0 0 50000 50000 0.05\n0 0 0\n";
  EXPECT_NE(error_of([&] { ReadBotlabMap(path); }).find("line 1: width x height 50000 x 50000 exceeds the limit"),
            std::string::npos);
  std::ofstream(path) << "0 0 10000 10000 0.05\n0 0 0\n";
  EXPECT_NE(error_of([&] { ReadBotlabMap(path); }).find("10000 x 10000 cells, but the file holds only"),
            std::string::npos);
  std::ofstream(path) << "0 0 3 1 1e300\n0 0 0\n";
  EXPECT_NE(error_of([&] { ReadBotlabMap(path); }).find("resolution 1e+300 is not in"), std::string::npos);
  std::ofstream(path) << "1e300 0 3 1 0.05\n0 0 0\n";
  EXPECT_NE(error_of([&] { ReadBotlabMap(path); }).find("is not within"), std::string::npos);
  const auto mai = test::TempPath("huge_movingai.map");
  std::ofstream(mai) << "type octile\nheight 100000\nwidth 100000\nmap\n....\n";
  EXPECT_NE(error_of([&] { ReadMovingAiMap(mai); }).find(mai + ": header width x height 100000 x 100000 exceeds"),
            std::string::npos);
  const auto pgm = test::TempPath("huge.pgm"), yaml = test::TempPath("huge.yaml");
  std::ofstream(pgm) << "P5\n# a comment\n60000 60000\n255\n";
  std::ofstream(yaml) << "image: huge.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n";
  EXPECT_NE(error_of([&] { ReadRosMap(yaml); }).find("huge.pgm: PGM header: width x height 60000 x 60000"),
            std::string::npos);
}

TEST(MapIoTest, MovingAiMapFlipsRowsAndHandlesCrlf) {
  const auto path = test::TempPath("m.map");
  std::ofstream(path) << "type octile\r\nheight 2\r\nwidth 3\r\nmap\r\n.@T\r\nG.S\r\n";
  const auto g = ReadMovingAiMap(path);
  ASSERT_EQ(g.width(), 3);
  EXPECT_LT(g.at(0, 1), 0);  // '.' top-left → row height-1
  EXPECT_GT(g.at(1, 1), 0);  // '@'
  EXPECT_GT(g.at(2, 1), 0);  // 'T'
  EXPECT_LT(g.at(2, 0), 0);  // 'S' passable
}

TEST(MapIoTest, SimplemapScansAreInsertedAtTheirKeyframePoses) {
  // One keyframe at (1, 2) facing +y, with a 3-beam scan that hits a wall 1 m ahead.
  mrpt::maps::CSimpleMap sm;
  auto scan = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
  scan->aperture = static_cast<float>(0.2);
  scan->maxRange = 10.0f;
  scan->resizeScan(3);
  for (size_t i = 0; i < 3; ++i) scan->setScanRange(i, 1.0f), scan->setScanRangeValidity(i, true);
  auto sf = std::make_shared<mrpt::obs::CSensoryFrame>();
  sf->insert(scan);
  auto pose = std::make_shared<mrpt::poses::CPose3DPDFGaussian>(mrpt::poses::CPose3D(1.0, 2.0, 0.0, M_PI / 2, 0, 0));
  sm.insert(pose, sf);
  const auto path = test::TempPath("one.simplemap.gz");
  ASSERT_TRUE(sm.saveToFile(path));
  std::string format;
  const auto g = ReadAnyMap(path, &format);
  EXPECT_EQ(format, "MRPT simplemap (scans inserted at 0.05 m)");
  int cx, cy;
  g.WorldToCell(1.0, 3.0, &cx, &cy);
  ASSERT_TRUE(g.IsInside(cx, cy));
  EXPECT_GT(g.at(cx, cy), 0);  // the middle beam's end: the wall
  g.WorldToCell(1.0, 2.5, &cx, &cy);
  ASSERT_TRUE(g.IsInside(cx, cy));
  EXPECT_LT(g.at(cx, cy), 0);  // cleared on the way
  g.WorldToCell(2.0, 2.0, &cx, &cy);
  ASSERT_TRUE(g.IsInside(cx, cy));
  EXPECT_EQ(g.at(cx, cy), 0);  // never seen
  EXPECT_TRUE(IsMapFile(path));
}

TEST(MapIoTest, SimplemapWithoutScansIsAnError) {
  mrpt::maps::CSimpleMap sm;
  sm.insert(std::make_shared<mrpt::poses::CPose3DPDFGaussian>(), std::make_shared<mrpt::obs::CSensoryFrame>());
  const auto path = test::TempPath("empty.simplemap");
  ASSERT_TRUE(sm.saveToFile(path));
  try {
    ReadMrptSimplemap(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": holds no 2D range scans"), std::string::npos) << e.what();
  }
}

// Replaces the first occurrence of `from` in the file with `to` (same length); false if absent.
bool PatchBytes(const std::string& path, const std::vector<uint8_t>& from, const std::vector<uint8_t>& to) {
  std::ifstream in(path, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = std::search(bytes.begin(), bytes.end(), from.begin(), from.end());
  if (at == bytes.end()) return false;
  std::copy(to.begin(), to.end(), at);
  test::WriteBytes(path, bytes);
  return true;
}

// The message ReadMrptGridmap throws for `path` (a failure when it does not throw).
std::string GridmapError(const std::string& path) {
  try {
    ReadMrptGridmap(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << path << ": expected an error";
  return "";
}

std::vector<uint8_t> FloatBytes(float f) {
  std::vector<uint8_t> b(4);
  std::memcpy(b.data(), &f, 4);
  return b;
}

// An MRPT gridmap whose resolution was changed from 0.05 to 1e-4 m declares 20,000 × 20,000 cells:
// MRPT would allocate 800 MB for a file of a few kilobytes. It is refused in a bounded trial read.
TEST(MapIoTest, MrptGridmapAskingForMoreThanItsSizeIsRefused) {
  mrpt::maps::COccupancyGridMap2D grid(-1.0f, 1.0f, -1.0f, 1.0f, 0.05f);
  const auto path = test::TempPath("huge.gridmap");
  {
    mrpt::io::CFileOutputStream out(path);  // uncompressed, so the resolution's bytes can be found
    auto arch = mrpt::serialization::archiveFrom(out);
    arch << grid;
  }
  EXPECT_EQ(ReadMrptGridmap(path).width(), 40);
  ASSERT_TRUE(PatchBytes(path, FloatBytes(0.05f), FloatBytes(1e-4f)));
  const std::string what = GridmapError(path);
  EXPECT_EQ(what.rfind(path + ": cannot read MRPT gridmap: ", 0), 0u) << what;
#if !defined(__SANITIZE_ADDRESS__)
  EXPECT_NE(what.find("asks for more memory than the 256 MB its size allows"), std::string::npos) << what;
#endif
}

TEST(MapIoTest, MrptExceptionsComeOutAsOneLineNamingTheFile) {
  const auto path = test::TempPath("garbage.gridmap");
  test::WriteBytes(path, {0x93, 'C', 'O', 'c', 'c', 'u', 'p', 'a', 'n',  'c', 'y', 'G',
                          'r',  'i', 'd', 'M', 'a', 'p', '2', 'D', 0x7f, 1,   2,   3});
  const std::string what = GridmapError(path);
  EXPECT_EQ(what.rfind(path + ": cannot read MRPT gridmap: ", 0), 0u) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;  // no backtrace
}

TEST(MapIoTest, SimplemapScansWithCorruptRangesCannotGrowTheGridWithoutBound) {
  mrpt::maps::CSimpleMap sm;
  for (const float range : {2.0f, 1e30f}) {
    auto scan = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
    scan->aperture = static_cast<float>(M_PI);
    scan->maxRange = 1e31f;
    scan->resizeScan(19);
    for (size_t i = 0; i < 19; ++i) {
      scan->setScanRange(i, range);
      scan->setScanRangeValidity(i, true);
    }
    auto sf = std::make_shared<mrpt::obs::CSensoryFrame>();
    sf->insert(scan);
    sm.insert(std::make_shared<mrpt::poses::CPose3DPDFGaussian>(), sf);
  }
  const auto path = test::TempPath("far.simplemap");
  ASSERT_TRUE(sm.saveToFile(path));
  const msgs::OccupancyGrid g = ReadMrptSimplemap(path);
  EXPECT_LE(static_cast<long long>(g.width()) * g.height(), kMaxMapCells);
  EXPECT_LT(g.width(), 1000);  // the sane scan's map, the far one left out
}

TEST(MapIoTest, SlamCheckpointRoundTrips) {
  const auto ini = test::TempPath("ck/slam_checkpoint.ini");
  std::filesystem::create_directories(std::filesystem::path(ini).parent_path());
  SlamCheckpoint c;
  c.pose = {1.25, -0.5, 0.75};
  c.odometry = {1.5, -0.25, 0.5};
  c.t_s = 30.25;
  c.scans = 232;
  WriteSlamCheckpoint(ini, Fixture(), c);
  const SlamCheckpoint back = ReadSlamCheckpoint(ini);
  EXPECT_EQ(back.map_path, (std::filesystem::path(ini).parent_path() / "slam_checkpoint.map").string());
  EXPECT_NEAR(back.pose.x, 1.25, 1e-12);
  EXPECT_NEAR(back.pose.theta, 0.75, 1e-12);
  EXPECT_NEAR(back.odometry.y, -0.25, 1e-12);
  EXPECT_EQ(back.scans, 232);
  EXPECT_EQ(ReadBotlabMap(back.map_path).cells(), Fixture().cells());
}

TEST(MapIoTest, PngIsWritten) {
  const auto path = test::TempPath("g.png");
  WriteMapPng(Fixture(), path);
  std::ifstream in(path, std::ios::binary);
  char sig[4] = {};
  in.read(sig, 4);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
}

}  // namespace
}  // namespace mbot::drivers

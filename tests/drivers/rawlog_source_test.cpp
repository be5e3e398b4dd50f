#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <iterator>

#include <fstream>

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/serialization/CArchive.h>

#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

TEST(RawlogSourceTest, ObservationsOnlyFormatIsReadInTimeOrder) {
  mrpt::obs::CRawlog rawlog;
  const auto t0 = mrpt::Clock::fromDouble(1000.0);
  auto odo = mrpt::obs::CObservationOdometry::Create();
  odo->sensorLabel = "ODOMETRY";
  odo->timestamp = mrpt::Clock::fromDouble(1000.5);
  odo->odometry = mrpt::poses::CPose2D(1.0, 2.0, 0.3);
  auto scan = mrpt::obs::CObservation2DRangeScan::Create();
  scan->sensorLabel = "LASER";
  scan->timestamp = t0;
  scan->aperture = M_PI;
  scan->resizeScan(181);
  for (size_t i = 0; i < 181; ++i) {
    scan->setScanRange(i, 2.0f);
    scan->setScanRangeValidity(i, i != 5);
  }
  rawlog.insert(odo);
  rawlog.insert(scan);
  const auto path = test::TempPath("obs.rawlog");
  ASSERT_TRUE(rawlog.saveToRawLogFile(path));

  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  EXPECT_EQ(src->Format(), "MRPT rawlog (observations only)");
  auto a = src->Next();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->kind, EventKind::kLidar);  // earlier timestamp first
  const auto& s = std::get<LidarScan>(a->payload);
  ASSERT_EQ(s.ranges_m.size(), 181u);
  EXPECT_EQ(s.ranges_m[5], 0.0f);  // invalid beam → no return
  EXPECT_NEAR(s.angles_rad[1] - s.angles_rad[0], M_PI / 180, 1e-6);
  auto b = src->Next();
  ASSERT_TRUE(b);
  EXPECT_EQ(b->kind, EventKind::kOdometry);
  EXPECT_EQ(b->t_us - a->t_us, 500000);
  EXPECT_NEAR(std::get<msgs::Pose2D>(b->payload).y, 2.0, 1e-9);
  EXPECT_FALSE(src->Next());
}

// A rawlog cut short keeps what was read, and says it was cut (MRPT's own loader stops quietly).
TEST(RawlogSourceTest, ARawlogCutShortIsReported) {
  mrpt::obs::CRawlog rawlog;
  for (int i = 0; i < 200; ++i) {
    auto odo = mrpt::obs::CObservationOdometry::Create();
    odo->sensorLabel = "ODOMETRY";
    odo->timestamp = mrpt::Clock::fromDouble(1000.0 + i);
    odo->odometry = mrpt::poses::CPose2D(0.01 * i, 0.0, 0.0);
    rawlog.insert(odo);
  }
  const auto whole = test::TempPath("whole.rawlog"), cut = test::TempPath("cut.rawlog");
  ASSERT_TRUE(rawlog.saveToRawLogFile(whole));
  std::ifstream in(whole, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() * 7 / 10));
  SourceOptions o;
  o.path = whole;
  auto full = OpenSource(o);
  EXPECT_FALSE(full->diagnostics().truncated_tail);
  o.path = cut;
  auto src = OpenSource(o);
  int n = 0;
  while (src->Next()) ++n;
  EXPECT_GT(n, 0);
  EXPECT_LT(n, 200);
  EXPECT_TRUE(src->diagnostics().truncated_tail);
}

// A scan whose beam count was changed to 2^31 - 1 makes MRPT's reader allocate 8 GB of aligned floats
// and write through the null pointer it gets back when that fails. The trial read in a bounded child
// finds the record; the entries before it are kept, like a file cut short.
TEST(RawlogSourceTest, ARecordThatCrashesMrptsReaderEndsTheReadWithAWarning) {
  const auto path = test::TempPath("crash.rawlog");
  {
    mrpt::io::CFileOutputStream out(path);  // uncompressed, so the count's bytes can be found
    auto arch = mrpt::serialization::archiveFrom(out);
    for (int i = 0; i < 6; ++i) {
      mrpt::obs::CObservation2DRangeScan scan;
      scan.sensorLabel = "LASER";
      scan.timestamp = mrpt::Clock::fromDouble(1000.0 + i);
      scan.aperture = M_PI;
      scan.resizeScan(i == 3 ? 171 : 181);  // the fourth scan's count is the one to corrupt
      for (size_t k = 0; k < scan.getScanSize(); ++k) scan.setScanRange(k, 2.0f);
      arch << scan;
    }
  }
  std::vector<uint8_t> bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::vector<uint8_t> count = {171, 0, 0, 0, 0, 0, 0, 0x40};  // 171, then the first range 2.0f
  auto at = std::search(bytes.begin(), bytes.end(), count.begin(), count.end());
  ASSERT_NE(at, bytes.end());
  at[0] = 0xff, at[1] = 0xff, at[2] = 0xff, at[3] = 0x7f;
  test::WriteBytes(path, bytes);

  SourceOptions o;
  o.path = path;
  auto src = OpenSource(o);
  int n = 0;
  while (src->Next()) ++n;
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(src->diagnostics().truncated_tail);
}

TEST(RawlogSourceTest, NotARawlogIsAnErrorNamingTheFile) {
  const auto path = test::TempPath("bad.rawlog");
  test::WriteBytes(path, {1, 2, 3, 4, 5, 6, 7, 8});
  SourceOptions o;
  o.path = path;
  try {
    auto src = OpenSource(o);
    size_t n = 0;
    while (src->Next()) ++n;
    EXPECT_EQ(n, 0u);  // MRPT may accept the file as empty; it must not invent events
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

}  // namespace
}  // namespace mbot::drivers

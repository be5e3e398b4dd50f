#include "mbot/lcm/lcm_log.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace mbot::lcmio {

namespace {

TEST(LcmLogReaderTest, ReadsRecordsInOrder) {
  std::vector<uint8_t> bytes;
  AppendLcmRecord(bytes, 0, 100, "A", {1, 2, 3});
  AppendLcmRecord(bytes, 1, 200, "BB", {});
  const auto path = test::TempPath("ok.log");
  test::WriteBytes(path, bytes);
  LcmLogReader r(path);
  auto a = r.Next();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->channel, "A");
  EXPECT_EQ(a->timestamp_us, 100);
  EXPECT_EQ(a->data, (std::vector<uint8_t>{1, 2, 3}));
  auto b = r.Next();
  ASSERT_TRUE(b);
  EXPECT_EQ(b->channel, "BB");
  EXPECT_EQ(b->file_offset, 28 + 1 + 3);
  EXPECT_FALSE(r.Next());
  EXPECT_EQ(r.resyncs(), 0);
  EXPECT_FALSE(r.truncated());
}

TEST(LcmLogReaderTest, ResynchronisesAfterGarbage) {
  std::vector<uint8_t> bytes;
  AppendLcmRecord(bytes, 0, 100, "A", {1});
  const size_t garbage_at = bytes.size();
  for (int i = 0; i < 37; ++i) bytes.push_back(static_cast<uint8_t>(0x55 + i));
  AppendLcmRecord(bytes, 1, 200, "B", {2});
  const auto path = test::TempPath("garbage.log");
  test::WriteBytes(path, bytes);
  LcmLogReader r(path);
  ASSERT_TRUE(r.Next());
  auto b = r.Next();
  ASSERT_TRUE(b);
  EXPECT_EQ(b->channel, "B");
  EXPECT_EQ(b->file_offset, static_cast<int64_t>(garbage_at + 37));
  EXPECT_EQ(r.resyncs(), 1);
  EXPECT_GE(r.skipped_bytes(), 36);
  EXPECT_FALSE(r.Next());
}

TEST(LcmLogReaderTest, CorruptLengthFieldResyncs) {
  std::vector<uint8_t> bytes;
  AppendLcmRecord(bytes, 0, 100, "A", {1});
  std::vector<uint8_t> bad;
  AppendLcmRecord(bad, 1, 150, "X", {9, 9});
  bad[20] = 0x7f;  // channel length becomes absurd
  bytes.insert(bytes.end(), bad.begin(), bad.end());
  AppendLcmRecord(bytes, 2, 200, "C", {3});
  const auto path = test::TempPath("badlen.log");
  test::WriteBytes(path, bytes);
  LcmLogReader r(path);
  std::vector<std::string> channels;
  while (auto rec = r.Next()) channels.push_back(rec->channel);
  EXPECT_EQ(channels, (std::vector<std::string>{"A", "C"}));
  EXPECT_EQ(r.resyncs(), 1);
}

TEST(LcmLogReaderTest, TruncatedTailIsReportedNotFatal) {
  std::vector<uint8_t> bytes;
  AppendLcmRecord(bytes, 0, 100, "A", {1, 2, 3, 4});
  AppendLcmRecord(bytes, 1, 200, "B", std::vector<uint8_t>(100, 7));
  bytes.resize(bytes.size() - 50);
  const auto path = test::TempPath("trunc.log");
  test::WriteBytes(path, bytes);
  LcmLogReader r(path);
  ASSERT_TRUE(r.Next());
  EXPECT_FALSE(r.Next());
  EXPECT_TRUE(r.truncated());
  // A header cut short is a truncated tail too.
  bytes.resize(28 + 1 + 4 + 10);
  test::WriteBytes(path, bytes);
  LcmLogReader r2(path);
  ASSERT_TRUE(r2.Next());
  EXPECT_FALSE(r2.Next());
  EXPECT_TRUE(r2.truncated());
}

TEST(LcmLogReaderTest, MissingFileThrowsNamingIt) {
  try {
    LcmLogReader r("/nonexistent/x.log");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.log"), std::string::npos);
  }
}

TEST(LcmLogWriterTest, RoundTripsThroughTheReader) {
  const auto path = test::TempPath("written.log");
  {
    LcmLogWriter w(path);
    const uint8_t d[] = {5, 6};
    w.Write(42, "CH", d, 2);
    w.Close();
  }
  LcmLogReader r(path);
  auto rec = r.Next();
  ASSERT_TRUE(rec);
  EXPECT_EQ(rec->timestamp_us, 42);
  EXPECT_EQ(rec->data, (std::vector<uint8_t>{5, 6}));
}

}  // namespace
}  // namespace mbot::lcmio

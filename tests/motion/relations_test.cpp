// The Kuemmerle et al. relations metric: reading a .relations file, scoring a trajectory, and the
// errors a file that does not fit the run gets.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "mbot/motion/relations.hpp"

namespace mbot::motion {
namespace {

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(Relations, ReadsTheBenchmarkFormat) {
  const std::string path = WriteTemp("rel_ok.relations",
                                     "# a comment\n976052905.167303 976052911.885496 -0.056990 -0.128430 0.000000 "
                                     "0.000000 0.000000 -1.682210\n\n10.5 11.25 1 2 0 0 0 0.5\n");
  const std::vector<Relation> r = ReadRelations(path);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].t1_us, 976052905167303);
  EXPECT_EQ(r[0].t2_us, 976052911885496);
  EXPECT_DOUBLE_EQ(r[0].delta.theta, -1.682210);
  EXPECT_EQ(r[1].line, 4);
  EXPECT_DOUBLE_EQ(r[1].delta.y, 2.0);
}

TEST(Relations, ABadLineIsAnErrorNamingFileAndLine) {
  const std::string path = WriteTemp("rel_bad.relations", "1 2 0 0 0 0 0 0\n1 2 0 0 0 0 zero 0\n");
  try {
    ReadRelations(path);
    FAIL() << "no error";
  } catch (const RelationsError& e) {
    EXPECT_NE(std::string(e.what()).find("rel_bad.relations:2"), std::string::npos) << e.what();
  }
}

// Values no relation can have are refused naming the line; a huge line is not echoed whole. A
// relation whose t2 comes before t1 is read (Intel's hand-checked file has six).
TEST(Relations, ImplausibleValuesAreRefusedAndLongLinesShortened) {
  auto error = [](const std::string& text) {
    try {
      ReadRelations(WriteTemp("rel_hostile.relations", text));
    } catch (const RelationsError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("1 2 0 0 0 0 0 0\n1 2 1e300 0 0 0 0 0\n").find("rel_hostile.relations:2: a relative position"),
            std::string::npos);
  EXPECT_NE(error("1 2 0 0 0 0 0 1e300\n").find(":1: an angle beyond 4 pi"), std::string::npos);
  const std::string huge = error("1 2 3 " + std::string(100000, '7') + "x\n");
  EXPECT_NE(huge.find(":1: a relation is eight numbers"), std::string::npos);
  EXPECT_LT(huge.size(), 400u);
  EXPECT_NE(huge.find("100007 bytes"), std::string::npos) << huge;
  EXPECT_EQ(ReadRelations(WriteTemp("rel_back.relations", "12.5 11.75 0.3 0 0 0 0 0.05\n")).size(), 1u);
}

TEST(Relations, ScoresTheErrorOfEachRelativeMotion) {
  std::map<int64_t, Pose2D> poses{{1'000'000, {0, 0, 0}}, {2'000'000, {1.0, 0, 0}}, {3'000'000, {1.0, 1.0, M_PI / 2}}};
  // Exact relations: no error.
  std::vector<Relation> rel{{1'000'000, 2'000'000, {1.0, 0, 0}, 1}, {2'000'000, 3'000'000, {0, 1.0, M_PI / 2}, 2}};
  RelationErrors e = ScoreRelations(rel, poses, "x.relations");
  EXPECT_EQ(e.scored, 2);
  EXPECT_NEAR(e.trans_m.mean, 0, 1e-12);
  EXPECT_NEAR(e.rot_deg.mean, 0, 1e-12);
  // The first relation says 1.1 m and 1° of turn: 0.1 m (in its own frame) and 1° off.
  rel[0].delta = {1.1, 0, M_PI / 180};
  e = ScoreRelations(rel, poses, "x.relations");
  EXPECT_NEAR(e.trans_m.mean, 0.05, 1e-9);
  EXPECT_NEAR(e.trans_m.std, 0.05, 1e-9);
  EXPECT_NEAR(e.rot_deg.mean, 0.5, 1e-9);
  EXPECT_NEAR(e.trans_sq_m2.mean, 0.005, 1e-9);
  EXPECT_NEAR(e.max_trans_m, 0.1, 1e-9);
  // Stamps within the tolerance match.
  rel[1].t2_us += 400;
  EXPECT_EQ(ScoreRelations(rel, poses, "x.relations").scored, 2);
}

TEST(Relations, AStampWithoutAPoseIsAnErrorNamingFileAndStamp) {
  std::map<int64_t, Pose2D> poses{{1'000'000, {}}, {2'000'000, {}}, {3'000'000, {}}};
  const std::vector<Relation> rel{{1'000'000, 2'500'000, {}, 7}};
  try {
    ScoreRelations(rel, poses, "intel.relations");
    FAIL() << "no error";
  } catch (const RelationsError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("intel.relations:7"), std::string::npos) << what;
    EXPECT_NE(what.find("2.500000"), std::string::npos) << what;
  }
  // Relations beyond the run (an interrupted one) are left out; none within it is an error.
  EXPECT_EQ(ScoreRelations({{1'000'000, 2'000'000, {}, 1}, {9'000'000, 9'500'000, {}, 2}}, poses, "f").scored, 1);
  EXPECT_THROW(ScoreRelations({{9'000'000, 9'500'000, {}, 1}}, poses, "f"), RelationsError);
}

}  // namespace
}  // namespace mbot::motion

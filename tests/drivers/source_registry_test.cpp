// The source registry: libs/drivers' own types, a type another library registers (detected,
// configured with its own keys, opened), and the errors.
#include <gtest/gtest.h>

#include <filesystem>

#include <fstream>

#include "mbot/common/config.hpp"
#include "mbot/drivers/source_options.hpp"
#include "test_util.hpp"

namespace mbot::drivers {

using namespace msgs;  // the event vocabulary
namespace {

// A source of `count` odometry events, registered as type "test_counter" for `.counter` files.
class CounterSource : public Source {
 public:
  explicit CounterSource(int count) : count_(count) {}
  std::optional<Event> Next() override {
    if (i_ >= count_) return std::nullopt;
    ++i_;
    return Event{i_ * 1000, i_ * 1000, "ODOMETRY", EventKind::kOdometry, msgs::Pose2D{double(i_), 0, 0}};
  }
  double Progress() const override { return count_ ? double(i_) / count_ : 1.0; }
  std::string Format() const override { return "counter"; }

 private:
  int count_, i_ = 0;
};

void RegisterCounter() {
  if (FindSourceType("test_counter")) return;
  RegisterSourceType({"test_counter", "counts",
                      [](const std::string& p) { return p.size() > 8 && p.substr(p.size() - 8) == ".counter"; }, 0,
                      [](config::Section& s, SourceOptions* o) {
                        o->extra = static_cast<int>(s.GetInt("count", 3, "events", 0, 100));
                      },
                      [](const SourceOptions& o) {
                        const int* n = std::any_cast<int>(&o.extra);
                        return std::make_unique<CounterSource>(n ? *n : 3);
                      }});
}

SourceOptions Parse(const std::string& ini) {
  const auto c = config::Config::FromString(ini, "t.ini");
  config::Section s = c.GetSection("source");
  SourceOptions o = ParseSourceOptions(s);
  s.Finish();
  return o;
}

TEST(SourceRegistry, HasDriversOwnTypesAndRejectsADuplicate) {
  for (const char* t : {"lcm_log", "rawlog", "carmen", "map", "astar_cases", "movingai", "motor_csv", "lcm_live"}) {
    EXPECT_NE(FindSourceType(t), nullptr) << t;
  }
  EXPECT_EQ(FindSourceType("nope"), nullptr);
  EXPECT_THROW(RegisterSourceType({"carmen", "again", nullptr, 0, nullptr, nullptr}), std::logic_error);
}

TEST(SourceRegistry, ARegisteredTypeIsDetectedConfiguredAndOpened) {
  RegisterCounter();
  const std::string path = test::TempPath("five.counter");
  std::ofstream(path) << "x";
  EXPECT_EQ(DetectFormat(path), "test_counter");
  const SourceOptions o = Parse("[source]\npath = " + path + "\ncount = 5\n");  // type = auto
  auto src = OpenSource(o);
  int n = 0;
  while (src->Next()) ++n;
  EXPECT_EQ(n, 5);
  // Its keys exist only for it.
  EXPECT_THROW(Parse("[source]\ntype = carmen\npath = " + path + "\ncount = 5\n"), config::ConfigError);
}

TEST(SourceRegistry, ErrorsNameThePath) {
  try {
    DetectFormat("/no/such/file.log");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/file.log: no such file"), std::string::npos) << e.what();
  }
  // A folder that is not an A* case set and holds no image (a folder of images is a camera's).
  const std::string folder = ::testing::TempDir() + "/source_registry_plain_folder";
  std::filesystem::create_directories(folder);
  try {
    DetectFormat(folder);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mbot::drivers

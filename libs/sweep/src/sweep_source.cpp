#include "mbot/sweep/sweep_source.hpp"

#include <memory>

#include <stdexcept>

#include "mbot/msgs/source.hpp"
#include "mbot/msgs/source.hpp"
#include "mbot/sweep/merge.hpp"

namespace mbot::sweep {
namespace {

class SweepFolderSource : public msgs::Source {
 public:
  std::optional<msgs::Event> Next() override { return std::nullopt; }
  double Progress() const override { return 1.0; }
  std::string Format() const override { return "sweep folder"; }
  bool events_expected() const override { return false; }
};

}  // namespace

void RegisterSweepSource() {
  if (msgs::FindSourceType("sweep")) return;
  msgs::RegisterSourceType(
      {"sweep", "a sweep folder (sweep.json, jobs.txt and jobs/<id>/ from a [sweep] config), for merge_sweep",
       [](const std::string& path) { return IsSweepFolder(path); }, -1, nullptr,
       [](const msgs::SourceOptions& o) -> std::unique_ptr<msgs::Source> {
         if (!IsSweepFolder(o.path)) throw std::runtime_error(o.path + ": not a sweep folder (no sweep.json in it)");
         return std::make_unique<SweepFolderSource>();
       },
       msgs::SourceType::Path::kFileOrFolder});
}

}  // namespace mbot::sweep

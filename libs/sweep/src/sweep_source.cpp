#include "mbot/sweep/sweep_source.hpp"

#include <memory>

#include "mbot/drivers/source.hpp"
#include "mbot/drivers/source_options.hpp"
#include "mbot/sweep/merge.hpp"

namespace mbot::sweep {
namespace {

class SweepFolderSource : public drivers::Source {
 public:
  std::optional<drivers::Event> Next() override { return std::nullopt; }
  double Progress() const override { return 1.0; }
  std::string Format() const override { return "sweep folder"; }
  bool events_expected() const override { return false; }
};

}  // namespace

void RegisterSweepSource() {
  if (drivers::FindSourceType("sweep")) return;
  drivers::RegisterSourceType(
      {"sweep", "a sweep folder (sweep.json, jobs.txt and jobs/<id>/ from a [sweep] config), for merge_sweep",
       [](const std::string& path) { return IsSweepFolder(path); }, -1, nullptr,
       [](const drivers::SourceOptions& o) -> std::unique_ptr<drivers::Source> {
         if (!IsSweepFolder(o.path)) throw std::runtime_error(o.path + ": not a sweep folder (no sweep.json in it)");
         return std::make_unique<SweepFolderSource>();
       }});
}

}  // namespace mbot::sweep

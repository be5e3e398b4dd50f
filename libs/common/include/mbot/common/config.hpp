// Strict INI configuration: `include` for shared defaults, `--set section.key=value` overrides, and
// typed getters that remember which keys were read so unknown keys are start-up errors naming the
// file, line, section and key.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mbot::config {

// Every configuration problem: the message already names file, line, section and key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a value came from: a file and line, or the command line (line 0, file "--set").
struct Origin {
  std::string file;
  int line = 0;
  std::string ToString() const;
};

struct Entry {
  std::string value;  // raw text, variables not yet expanded
  Origin origin;
};

// One key as a stage documents it (for --list-stages): what it is, its type and its default.
struct KeyDoc {
  std::string key;
  std::string type;           // "string", "int", "double", "bool", "list", "path"
  std::string default_value;  // empty with required = true
  bool required = false;
  std::string doc;
};

class Section;

// A planar pose read from a configuration key. In INI files every pose is written
// `x, y, theta_deg`: metres, metres, degrees counter-clockwise (converted to radians here).
struct PoseValue {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

// The effective configuration after includes and overrides.
class Config {
 public:
  // Reads `path`, resolving `include = file` lines (relative to the including file) first, so the
  // including file overrides what it includes. Throws ConfigError with file and line.
  static Config Load(const std::string& path);
  // Parses INI text as if it were a file called `name` (tests, inline fixtures). Includes resolve
  // relative to `base_dir`.
  static Config FromString(const std::string& text, const std::string& name = "<string>",
                           const std::string& base_dir = ".");

  // Applies one `section.key=value` override. Throws ConfigError when malformed.
  void Set(const std::string& assignment);
  // Removes `section.key` (what an included file set that this run must not have: --unset).
  // Throws ConfigError when the configuration has no such key.
  void Unset(const std::string& name);

  bool HasSection(const std::string& name) const { return sections_.count(name) > 0; }
  std::vector<std::string> SectionNames() const;
  // A reader over one section (an empty one when the file has no such section).
  Section GetSection(const std::string& name) const;
  // Origin of the section header that first introduced it (for "unused section" errors).
  Origin SectionOrigin(const std::string& name) const;

  // The effective configuration as INI text, each value followed by where it was set.
  std::string ToIni() const;
  const std::string& main_file() const { return main_file_; }

 private:
  void ParseText(const std::string& text, const std::string& file, const std::string& base_dir,
                 std::vector<std::string>& include_stack);
  void ParseFile(const std::string& path, std::vector<std::string>& include_stack);

  std::map<std::string, std::map<std::string, Entry>> sections_;
  std::map<std::string, Origin> section_origins_;
  std::string main_file_;
};

// A reader over one section. Each getter records the key as known; Finish() then rejects keys
// nobody asked for. In describe mode (for --list-stages) the getters return defaults and record
// the documentation instead of reading anything.
class Section {
 public:
  Section(std::string name, const std::map<std::string, Entry>* entries, std::string file = "");
  static Section Describe(std::string name);

  const std::string& name() const { return name_; }

  std::string GetString(const std::string& key, const std::string& def, const std::string& doc);
  std::string RequireString(const std::string& key, const std::string& doc);
  // Like GetString, with `${datasets}` (MBOT_DATASETS_DIR) and `${config_dir}` expanded.
  std::string GetPath(const std::string& key, const std::string& def, const std::string& doc);
  std::string RequirePath(const std::string& key, const std::string& doc);
  long long GetInt(const std::string& key, long long def, const std::string& doc,
                   long long min = std::numeric_limits<long long>::min(),
                   long long max = std::numeric_limits<long long>::max());
  double GetDouble(const std::string& key, double def, const std::string& doc,
                   double min = -std::numeric_limits<double>::infinity(),
                   double max = std::numeric_limits<double>::infinity());
  bool GetBool(const std::string& key, bool def, const std::string& doc);
  // Comma-separated list; whitespace around items is trimmed, empty items dropped.
  std::vector<std::string> GetList(const std::string& key, const std::vector<std::string>& def, const std::string& doc);
  // One of `choices`; anything else is an error listing them.
  std::string GetChoice(const std::string& key, const std::string& def, const std::vector<std::string>& choices,
                        const std::string& doc);

  // One pose, `x, y, theta_deg` (see PoseValue).
  PoseValue GetPose(const std::string& key, const PoseValue& def, const std::string& doc);
  // Poses, `x, y, theta_deg` each, separated by `;` (or all by commas, in threes).
  std::vector<PoseValue> GetPoses(const std::string& key, const std::vector<PoseValue>& def, const std::string& doc);
  // One of an enum's names; anything else is an error listing them.
  template <typename E>
  E GetEnum(const std::string& key, E def, const std::vector<std::pair<std::string, E>>& names,
            const std::string& doc) {
    std::vector<std::string> choices;
    std::string def_name;
    for (const auto& [name, value] : names) {
      choices.push_back(name);
      if (value == def) def_name = name;
    }
    const std::string chosen = GetChoice(key, def_name, choices, doc);
    for (const auto& [name, value] : names) {
      if (name == chosen) return value;
    }
    return def;
  }

  bool Has(const std::string& key) const;
  // The keys the section holds (sorted), for sections whose keys are names the user chose (a
  // sweep's axis values). Reading one with a getter still marks it known.
  std::vector<std::string> Keys() const;
  // Marks a key as known without reading it (e.g. `type`, which the registry consumed).
  void Accept(const std::string& key);
  // Throws ConfigError for the first key that no getter asked for, listing the known keys.
  void Finish() const;

  // An error about `key` carrying its origin: "file:line: [section] key: message".
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;

  const std::vector<KeyDoc>& docs() const { return docs_; }
  bool describing() const { return entries_ == nullptr; }

 private:
  const Entry* Find(const std::string& key, const std::string& type, const std::string& def, bool required,
                    const std::string& doc);
  std::string Expand(const Entry& entry, const std::string& key) const;

  std::string name_;
  const std::map<std::string, Entry>* entries_ = nullptr;
  std::string file_;  // the configuration file, named in errors about keys that are missing
  std::vector<std::string> known_;
  std::vector<KeyDoc> docs_;
};

// Poses as GetPoses reads them: `x, y, theta_deg` each, separated by `; ` (6 significant digits).
std::string FormatPoses(const std::vector<PoseValue>& poses);

// The folder the `${datasets}` variable expands to: $MBOT_DATASETS_DIR if set, otherwise the
// build's default (CMake MBOT_DATASETS_DIR).
std::string DatasetsDir();

}  // namespace mbot::config

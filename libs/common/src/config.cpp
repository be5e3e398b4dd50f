#include "mbot/common/config.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mbot/common/strings.hpp"

namespace fs = std::filesystem;

namespace mbot::config {
namespace {

// Drops a comment that starts a line, or an inline one that follows whitespace (`key = 1  # why`).
std::string StripComment(const std::string& line) {
  const std::string t = Trim(line);
  if (t.empty() || t[0] == '#' || t[0] == ';') return "";
  for (size_t i = 1; i < line.size(); ++i) {
    if ((line[i] == '#' || line[i] == ';') && (line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return line.substr(0, i);
    }
  }
  return line;
}

bool ValidName(const std::string& s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

std::string Join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
  return out;
}

}  // namespace

std::string Origin::ToString() const {
  if (line <= 0) return file.empty() ? std::string("--set") : file;
  return file + ":" + std::to_string(line);
}

std::string DatasetsDir() {
  if (const char* env = std::getenv("MBOT_DATASETS_DIR"); env && *env) return env;
  return MBOT_DEFAULT_DATASETS_DIR;
}

Config Config::Load(const std::string& path) {
  Config c;
  c.main_file_ = path;
  std::vector<std::string> stack;
  c.ParseFile(path, stack);
  return c;
}

Config Config::FromString(const std::string& text, const std::string& name, const std::string& base_dir) {
  Config c;
  c.main_file_ = name;
  std::vector<std::string> stack{name};
  c.ParseText(text, name, base_dir, stack);
  return c;
}

void Config::ParseFile(const std::string& path, std::vector<std::string>& stack) {
  std::error_code ec;
  const std::string canonical = fs::weakly_canonical(path, ec).string();
  if (std::find(stack.begin(), stack.end(), canonical) != stack.end()) {
    throw ConfigError(path + ": include cycle (" + Join(stack, " -> ") + " -> " + canonical + ")");
  }
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open configuration file");
  std::stringstream ss;
  ss << in.rdbuf();
  stack.push_back(canonical);
  const std::string dir = fs::path(path).parent_path().string();
  ParseText(ss.str(), path, dir.empty() ? "." : dir, stack);
  stack.pop_back();
}

void Config::ParseText(const std::string& text, const std::string& file, const std::string& base_dir,
                       std::vector<std::string>& stack) {
  std::istringstream in(text);
  std::string raw;
  std::string section;                                          // empty until the first [section]
  std::map<std::string, std::map<std::string, int>> seen_here;  // duplicate detection per file
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = Trim(StripComment(raw));
    if (line.empty()) continue;
    const std::string where = file + ":" + std::to_string(line_no);
    if (line.front() == '[') {
      if (line.back() != ']') throw ConfigError(where + ": malformed section header '" + line + "'");
      section = Trim(line.substr(1, line.size() - 2));
      if (!ValidName(section)) throw ConfigError(where + ": invalid section name '" + section + "'");
      sections_[section];
      section_origins_.emplace(section, Origin{file, line_no});
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos) {
      throw ConfigError(where + ": expected 'key = value' or '[section]', got '" + line + "'");
    }
    const std::string key = Trim(line.substr(0, eq));
    const std::string value = Trim(line.substr(eq + 1));
    if (!ValidName(key)) throw ConfigError(where + ": invalid key name '" + key + "'");
    if (section.empty()) {
      if (key != "include") {
        throw ConfigError(where + ": key '" + key +
                          "' outside any section (only 'include' may come before the first "
                          "[section])");
      }
      if (value.empty()) throw ConfigError(where + ": include needs a file name");
      const fs::path inc = fs::path(value).is_absolute() ? fs::path(value) : fs::path(base_dir) / value;
      try {
        ParseFile(inc.string(), stack);
      } catch (const ConfigError& e) {
        throw ConfigError(std::string(e.what()) + "\n  included from " + where);
      }
      continue;
    }
    if (auto it = seen_here[section].find(key); it != seen_here[section].end()) {
      throw ConfigError(where + ": [" + section + "] " + key + ": set twice in this file (first at line " +
                        std::to_string(it->second) + ")");
    }
    seen_here[section][key] = line_no;
    sections_[section][key] = Entry{value, Origin{file, line_no}};
  }
}

void Config::Set(const std::string& assignment) {
  const auto eq = assignment.find('=');
  const auto dot = assignment.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq) {
    throw ConfigError("--set " + assignment + ": expected section.key=value");
  }
  const std::string section = Trim(assignment.substr(0, dot));
  const std::string key = Trim(assignment.substr(dot + 1, eq - dot - 1));
  if (!ValidName(section) || !ValidName(key) || key.find('.') != std::string::npos) {
    throw ConfigError("--set " + assignment + ": expected section.key=value");
  }
  sections_[section][key] = Entry{Trim(assignment.substr(eq + 1)), Origin{"--set", 0}};
  section_origins_.emplace(section, Origin{"--set", 0});
}

void Config::Unset(const std::string& name) {
  const auto dot = name.find('.');
  const std::string section = dot == std::string::npos ? "" : Trim(name.substr(0, dot));
  const std::string key = dot == std::string::npos ? "" : Trim(name.substr(dot + 1));
  auto it = sections_.find(section);
  if (dot == std::string::npos || it == sections_.end() || it->second.erase(key) == 0) {
    throw ConfigError("--unset " + name + ": no such key in the configuration (expected section.key)");
  }
}

std::vector<std::string> Config::SectionNames() const {
  std::vector<std::string> names;
  for (const auto& [name, entries] : sections_) names.push_back(name);
  return names;
}

Section Config::GetSection(const std::string& name) const {
  static const std::map<std::string, Entry> kEmpty;
  auto it = sections_.find(name);
  return Section(name, it == sections_.end() ? &kEmpty : &it->second, main_file_);
}

Origin Config::SectionOrigin(const std::string& name) const {
  auto it = section_origins_.find(name);
  return it == section_origins_.end() ? Origin{main_file_, 0} : it->second;
}

std::string Config::ToIni() const {
  std::ostringstream out;
  out << "# effective configuration of " << main_file_ << " (after includes and --set)\n";
  for (const auto& [name, entries] : sections_) {
    out << "\n[" << name << "]\n";
    for (const auto& [key, e] : entries) {
      out << key << " = " << e.value << "    # " << e.origin.ToString() << "\n";
    }
  }
  return out.str();
}

// ---------------------------------------------------------------------------------------------

Section::Section(std::string name, const std::map<std::string, Entry>* entries, std::string file)
    : name_(std::move(name)), entries_(entries), file_(std::move(file)) {}

Section Section::Describe(std::string name) { return Section(std::move(name), nullptr); }

bool Section::Has(const std::string& key) const { return entries_ && entries_->count(key) > 0; }

std::vector<std::string> Section::Keys() const {
  std::vector<std::string> keys;
  if (entries_) {
    for (const auto& [key, entry] : *entries_) keys.push_back(key);
  }
  return keys;
}

void Section::Accept(const std::string& key) { known_.push_back(key); }

void Section::Fail(const std::string& key, const std::string& message) const {
  std::string where = file_.empty() ? "" : file_ + ": ";
  if (entries_) {
    if (auto it = entries_->find(key); it != entries_->end()) where = it->second.origin.ToString() + ": ";
  }
  throw ConfigError(where + "[" + name_ + "] " + key + ": " + message);
}

const Entry* Section::Find(const std::string& key, const std::string& type, const std::string& def, bool required,
                           const std::string& doc) {
  known_.push_back(key);
  if (describing()) {
    // Documented once: source types that share a key (the channel roles) each read it.
    if (std::none_of(docs_.begin(), docs_.end(), [&](const KeyDoc& d) { return d.key == key; })) {
      docs_.push_back(KeyDoc{key, type, def, required, doc});
    }
    return nullptr;
  }
  auto it = entries_->find(key);
  if (it == entries_->end()) {
    if (required)
      throw ConfigError((file_.empty() ? "" : file_ + ": ") + "[" + name_ + "] " + key + ": required key is missing (" +
                        doc + ")");
    return nullptr;
  }
  return &it->second;
}

std::string Section::Expand(const Entry& entry, const std::string& key) const {
  std::string out;
  const std::string& v = entry.value;
  for (size_t i = 0; i < v.size();) {
    if (v.compare(i, 2, "${") == 0) {
      const auto end = v.find('}', i);
      if (end == std::string::npos) Fail(key, "unterminated '${' in '" + v + "'");
      const std::string var = v.substr(i + 2, end - i - 2);
      if (var == "datasets") {
        out += DatasetsDir();
      } else if (var == "config_dir") {
        const std::string dir = fs::path(entry.origin.file).parent_path().string();
        out += (entry.origin.line <= 0 || dir.empty()) ? "." : dir;
      } else {
        Fail(key, "unknown variable ${" + var + "} (known: ${datasets}, ${config_dir})");
      }
      i = end + 1;
    } else {
      out += v[i++];
    }
  }
  return out;
}

std::string Section::GetString(const std::string& key, const std::string& def, const std::string& doc) {
  const Entry* e = Find(key, "string", def, false, doc);
  return e ? e->value : def;
}

std::string Section::RequireString(const std::string& key, const std::string& doc) {
  const Entry* e = Find(key, "string", "", true, doc);
  return e ? e->value : "";
}

std::string Section::GetPath(const std::string& key, const std::string& def, const std::string& doc) {
  const Entry* e = Find(key, "path", def, false, doc);
  return e ? Expand(*e, key) : Expand(Entry{def, Origin{}}, key);
}

std::string Section::RequirePath(const std::string& key, const std::string& doc) {
  const Entry* e = Find(key, "path", "", true, doc);
  if (e && e->value.empty()) Fail(key, "must not be empty");
  return e ? Expand(*e, key) : "";
}

long long Section::GetInt(const std::string& key, long long def, const std::string& doc, long long min, long long max) {
  const Entry* e = Find(key, "int", std::to_string(def), false, doc);
  if (!e) return def;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(e->value.c_str(), &end, 10);
  if (e->value.empty() || *end != '\0' || errno == ERANGE) {
    Fail(key, "expected an integer, got '" + e->value + "'");
  }
  if (v < min || v > max) {
    Fail(key, "value " + e->value + " out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  }
  return v;
}

double Section::GetDouble(const std::string& key, double def, const std::string& doc, double min, double max) {
  std::ostringstream d;
  d << def;
  const Entry* e = Find(key, "double", d.str(), false, doc);
  if (!e) return def;
  char* end = nullptr;
  const double v = std::strtod(e->value.c_str(), &end);
  if (e->value.empty() || *end != '\0' || !std::isfinite(v)) {
    Fail(key, "expected a finite number, got '" + e->value + "'");
  }
  if (v < min || v > max) {
    std::ostringstream r;
    r << "value " << e->value << " out of range [" << min << ", " << max << "]";
    Fail(key, r.str());
  }
  return v;
}

bool Section::GetBool(const std::string& key, bool def, const std::string& doc) {
  const Entry* e = Find(key, "bool", def ? "true" : "false", false, doc);
  if (!e) return def;
  std::string v = e->value;
  std::transform(v.begin(), v.end(), v.begin(), ::tolower);
  if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
  if (v == "false" || v == "0" || v == "no" || v == "off") return false;
  Fail(key, "expected true or false, got '" + e->value + "'");
}

std::vector<std::string> Section::GetList(const std::string& key, const std::vector<std::string>& def,
                                          const std::string& doc) {
  const Entry* e = Find(key, "list", Join(def, ", "), false, doc);
  if (!e) return def;
  std::vector<std::string> out;
  std::stringstream ss(e->value);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = Trim(item);
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::vector<PoseValue> Section::GetPoses(const std::string& key, const std::vector<PoseValue>& def,
                                         const std::string& doc) {
  const Entry* e =
      Find(key, "poses", FormatPoses(def), false, doc + " (x, y, theta_deg per pose; poses separated by ';')");
  if (!e) return def;
  std::string text = e->value;
  std::replace(text.begin(), text.end(), ';', ',');
  std::vector<double> numbers;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = Trim(item);
    if (item.empty()) continue;
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v) || std::abs(v) > 1e6) {
      Fail(key, "'" + item + "' is not a finite number of at most 1e6 (expected x, y, theta_deg per pose)");
    }
    numbers.push_back(v);
  }
  if (numbers.size() % 3 != 0) {
    Fail(key, std::to_string(numbers.size()) + " numbers do not make x, y, theta_deg triples");
  }
  std::vector<PoseValue> poses;
  for (size_t i = 0; i + 2 < numbers.size(); i += 3)
    poses.push_back({numbers[i], numbers[i + 1], numbers[i + 2] * M_PI / 180.0});
  return poses;
}

PoseValue Section::GetPose(const std::string& key, const PoseValue& def, const std::string& doc) {
  const std::vector<PoseValue> poses = GetPoses(key, {def}, doc);
  if (poses.size() != 1) Fail(key, "expected one pose, x, y, theta_deg");
  return poses[0];
}

std::string Section::GetChoice(const std::string& key, const std::string& def, const std::vector<std::string>& choices,
                               const std::string& doc) {
  const Entry* e = Find(key, "string", def, false, doc + " (one of: " + Join(choices, ", ") + ")");
  if (!e) return def;
  if (std::find(choices.begin(), choices.end(), e->value) == choices.end()) {
    Fail(key, "'" + e->value + "' is not one of: " + Join(choices, ", "));
  }
  return e->value;
}

void Section::Finish() const {
  if (!entries_) return;
  for (const auto& [key, entry] : *entries_) {
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) {
      std::vector<std::string> known = known_;
      std::sort(known.begin(), known.end());
      known.erase(std::unique(known.begin(), known.end()), known.end());
      Fail(key, "unknown key (known keys: " + (known.empty() ? std::string("none") : Join(known, ", ")) + ")");
    }
  }
}

std::string FormatPoses(const std::vector<PoseValue>& poses) {
  std::ostringstream o;
  o.precision(6);
  for (size_t i = 0; i < poses.size(); ++i) {
    o << (i ? "; " : "") << poses[i].x_m << ", " << poses[i].y_m << ", " << poses[i].theta_rad * 180.0 / M_PI;
  }
  return o.str();
}

}  // namespace mbot::config

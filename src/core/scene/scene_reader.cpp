// Typed, range-checked reading of scene YAML nodes (see scene_reader.h).
#include "scene_reader.h"

#include <cmath>
#include <limits>
#include <set>
#include <sstream>

namespace birkhoff_cart {
namespace scene_detail {

std::string join_names(const std::vector<std::string>& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

void SceneReader::fail(const std::string& key, const std::string& problem) const {
  throw SceneError(file_, key, problem);
}

std::string SceneReader::join(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

void SceneReader::require_map(const YAML::Node& node, const std::string& key,
                              const std::vector<std::string>& allowed) const {
  if (!node.IsMap()) fail(key.empty() ? "(document)" : key, "must be a map of keys");
  std::set<std::string> seen;
  for (const auto& entry : node) {
    if (!entry.first.IsScalar()) fail(key.empty() ? "(document)" : key, "has a key that is not a plain name");
    const std::string name = entry.first.Scalar();
    bool known = false;
    for (const auto& candidate : allowed) known = known || candidate == name;
    if (!known) fail(join(key, name), "unknown key (allowed here: " + join_names(allowed) + ")");
    if (!seen.insert(name).second) fail(join(key, name), "given twice");
  }
}

bool SceneReader::has(const YAML::Node& parent, const std::string& name) const {
  return static_cast<bool>(parent[name]);
}

YAML::Node SceneReader::required(const YAML::Node& parent, const std::string& parent_key,
                                 const std::string& name) const {
  const YAML::Node child = parent[name];
  if (!child) fail(join(parent_key, name), "missing (required)");
  if (child.IsNull()) fail(join(parent_key, name), "has no value");
  return child;
}

double SceneReader::number(const YAML::Node& node, const std::string& key, Range range) const {
  if (!node.IsScalar()) fail(key, "must be a number");
  double value = 0.0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "must be a number, got '" + node.Scalar() + "'");
  }
  std::ostringstream got;
  got.precision(17);
  got << value;
  if (!std::isfinite(value)) fail(key, "must be finite, got " + got.str());
  if (range == Range::kPositive && !(value > 0.0)) fail(key, "must be > 0, got " + got.str());
  if (range == Range::kNonNegative && !(value >= 0.0)) fail(key, "must be >= 0, got " + got.str());
  return value;
}

double SceneReader::required_number(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                                    Range range) const {
  return number(required(parent, parent_key, name), join(parent_key, name), range);
}

double SceneReader::optional_number(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                                    Range range, double fallback) const {
  if (!has(parent, name)) return fallback;
  return required_number(parent, parent_key, name, range);
}

int SceneReader::optional_positive_integer(const YAML::Node& parent, const std::string& parent_key,
                                           const std::string& name, int fallback) const {
  if (!has(parent, name)) return fallback;
  const std::string key = join(parent_key, name);
  const YAML::Node node = required(parent, parent_key, name);
  if (!node.IsScalar()) fail(key, "must be an integer");
  int value = 0;
  try {
    value = node.as<int>();
  } catch (const YAML::Exception&) {
    fail(key, "must be an integer, got '" + node.Scalar() + "'");
  }
  if (value < 1) fail(key, "must be >= 1, got " + std::to_string(value));
  return value;
}

std::string SceneReader::text(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) fail(key, "must be a string");
  return node.Scalar();
}

std::string SceneReader::choice(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                                const std::vector<std::string>& choices) const {
  const std::string key = join(parent_key, name);
  const std::string value = text(required(parent, parent_key, name), key);
  for (const auto& candidate : choices) {
    if (candidate == value) return value;
  }
  fail(key, "'" + value + "' is not one of: " + join_names(choices));
}

bool SceneReader::optional_boolean(const YAML::Node& parent, const std::string& parent_key, const std::string& name,
                                   bool fallback) const {
  if (!has(parent, name)) return fallback;
  const std::string key = join(parent_key, name);
  const YAML::Node node = required(parent, parent_key, name);
  if (!node.IsScalar()) fail(key, "must be true or false");
  try {
    return node.as<bool>();
  } catch (const YAML::Exception&) {
    fail(key, "must be true or false, got '" + node.Scalar() + "'");
  }
}

}  // namespace scene_detail
}  // namespace birkhoff_cart

// The `accuracy` section of a scene file (docs/scenes.md "accuracy", docs/accuracy.md §2):
//
//   accuracy:
//     energy_balance_relative: {warn: 1.0e-4, error: 1.0e-2}   # or: off
//     p2_balance: off
//     ...
//
// Each key is optional and keeps its default when absent; `off` disables a quantity.
#include <iterator>
#include <string>
#include <vector>

#include "scene_reader.h"

namespace birkhoff_cart {
namespace scene_detail {

AccuracyRequirements read_accuracy(const SceneReader& reader, const YAML::Node& node) {
  AccuracyRequirements requirements;
  if (!node || node.IsNull()) return requirements;
  const std::vector<AccuracyQuantity> quantities(std::begin(kLimitedAccuracyQuantities),
                                                  std::end(kLimitedAccuracyQuantities));
  std::vector<std::string> names;
  for (AccuracyQuantity quantity : quantities) names.push_back(to_string(quantity));
  reader.require_map(node, "accuracy", names);
  for (AccuracyQuantity quantity : quantities) {
    const std::string name = to_string(quantity);
    if (!reader.has(node, name)) continue;
    const std::string key = SceneReader::join("accuracy", name);
    const YAML::Node limit_node = reader.required(node, "accuracy", name);
    AccuracyLimit& limit = requirements.limit(quantity);
    if (limit_node.IsScalar() && limit_node.Scalar() == "off") {
      limit.enabled = false;
      continue;
    }
    if (!limit_node.IsMap()) reader.fail(key, "must be 'off' or a map {warn: W, error: E} with 0 < W <= E");
    reader.require_map(limit_node, key, {"warn", "error"});
    limit.enabled = true;
    limit.warn = reader.required_number(limit_node, key, "warn", Range::kPositive);
    limit.error = reader.required_number(limit_node, key, "error", Range::kPositive);
    if (limit.warn > limit.error) reader.fail(SceneReader::join(key, "warn"), "must not exceed " + key + ".error");
  }
  return requirements;
}

}  // namespace scene_detail
}  // namespace birkhoff_cart

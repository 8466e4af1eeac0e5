// The node's schedules of instants (publishing, diagnostics): start + k·period [s], k = 1, 2, ...
#pragma once

#include <cstdint>

namespace birkhoff_cart {

/// One schedule of instants start + k·period [s], k = index, index + 1, ...: advances `index` past
/// every instant at or before `time` + `margin` [s] (half a step, so round-off in t does not move an
/// instant to the next step). True when at least one instant was passed.
inline bool pass_due_instants(double start, double period, double time, double margin, std::uint64_t& index) {
  bool passed = false;
  while (start + static_cast<double>(index) * period <= time + margin) {
    passed = true;
    ++index;
  }
  return passed;
}

}  // namespace birkhoff_cart

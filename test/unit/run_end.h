// A scene's run to its end through Simulation, for the unit tests that judge where a run ends
// (adaptive_step_control_test, global_error_estimate_test). Header-only: every test/unit/*.cpp is
// its own executable.
#pragma once

#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart_test {

/// The state at a run's end and the run's work.
struct RunEnd {
  birkhoff_cart::CartState end;
  birkhoff_cart::StepStatistics statistics;
};

/// `scene` run to its end time in one advance of its outputs.
inline RunEnd run_to_end_time(const birkhoff_cart::Scene& scene) {
  birkhoff_cart::Simulation simulation(scene);
  simulation.advance_output_to(simulation.end_time());
  return {simulation.state(), simulation.statistics()};
}

}  // namespace birkhoff_cart_test

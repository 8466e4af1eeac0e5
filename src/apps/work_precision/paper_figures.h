// work_precision: the paper's figures 1–2 (relative error of π1 against the closed form).
#pragma once

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>

#include "birkhoff_cart/core/reference_solution.h"
#include "birkhoff_cart/core/simulation.h"
#include "ours.h"

namespace birkhoff_cart {
namespace work_precision {

constexpr double kPaperStep = 1e-3;       // the paper's τ [s]
constexpr double kPaperEndMargin = 0.05;  // paper window ends at π − 0.05 [s]

/// Relative error of π1 against the closed form at τ = 0.001 (every 10 steps), on the paper's
/// window (π/2, π − 0.05) and on (0.05, π − 0.05), which includes π1 = 0.
inline void write_paper_relative_error(const Scene& paper_scene, std::FILE* out) {
  std::fprintf(out, "window,method,form,t,arc_length,arc_length_exact,relative_error\n");
  struct Window {
    const char* name;
    double start;  // [s]
  };
  const Window windows[] = {{"paper", M_PI / 2.0}, {"wide", kPaperEndMargin}};
  const std::pair<std::string, std::string> methods[] = {
      {"birkhoff2", "paper"}, {"birkhoff2", "autonomous"}, {"rk2", "paper"}, {"birkhoff4", "paper"}, {"rk4", "paper"}};
  for (const Window& window : windows) {
    Scene scene = paper_scene;
    // On the analytic family through the paper's state (π1 = 1 at t = π/2): χ = t, ω1 = 1/sin t,
    // π1 = 1 + ln tan(t/2) (docs eq. (3.9)).
    const PaperAnalyticSolution family{paper_scene.initial_state};
    scene.initial_state = family.at(window.start);
    scene.duration = (M_PI - kPaperEndMargin) - window.start;
    const std::uint64_t steps = static_cast<std::uint64_t>(std::floor(scene.duration / kPaperStep));
    for (const auto& [method, form] : methods) {
      Scene configured_scene = configured(scene, method, kPaperStep, 1e-10);
      configured_scene.integrator.birkhoffian_form = form;
      const PaperAnalyticSolution exact{scene.initial_state};
      try {
        Simulation sim(configured_scene);
        for (std::uint64_t k = 1; k <= steps; ++k) {
          sim.step();
          if (k % 10 == 0 || k == steps) {
            const CartState& s = sim.state();
            const double truth = exact.at(s.time).arc_length;
            std::fprintf(out, "%s,%s,%s,%.6f,%.12e,%.12e,%.6e\n", window.name, method.c_str(), form.c_str(), s.time,
                         s.arc_length, truth, std::abs(s.arc_length - truth) / std::abs(truth));
          }
        }
      } catch (const std::exception& error) {
        std::fprintf(stderr, "paper %s %s/%s: %s\n", window.name, method.c_str(), form.c_str(), error.what());
      }
    }
  }
  std::fflush(out);
}

}  // namespace work_precision
}  // namespace birkhoff_cart

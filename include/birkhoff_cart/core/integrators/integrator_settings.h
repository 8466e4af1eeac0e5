// The integrator a scene or a caller chooses, with its settings: plain data read by the registry
// (cart_binding/integrator_registry.h). Defaults match docs/scenes.md, "integrator".
#pragma once

#include <string>
#include <vector>

namespace birkhoff_cart {

/// The Birkhoffian form of the cart the members step (docs/birkhoffian.md).
enum class BirkhoffianForm {
  kAutonomous,  ///< "autonomous": z = (π1, χ, p1, p2), K = K₀
  kPaper,       ///< "paper": K = eᵗ J per pair, the structure epoch reset at every step
};

/// How the steps are chosen.
enum class StepControl {
  kFixed,       ///< "fixed": steps of step_size
  kReversible,  ///< "reversible": the reversible controller's steps (docs/birkhoffian.md §11)
  kAdaptive,    ///< "adaptive": error-per-step control on the member's estimate (docs/birkhoffian.md §12)
};

/// The text of a form or a control in scene files, on the command line and in messages.
const char* to_string(BirkhoffianForm form);
const char* to_string(StepControl control);

/// Every form's and every control's text, in the order the enums declare them.
const std::vector<std::string>& birkhoffian_form_names();
const std::vector<std::string>& step_control_names();

/// The form or control `text` names. Throws std::invalid_argument naming `text`, listing the known
/// texts and the closest one to a typo ("unknown birkhoffian_form 'autonomus' (known: autonomous,
/// paper; did you mean 'autonomous'?)").
BirkhoffianForm parse_birkhoffian_form(const std::string& text);
StepControl parse_step_control(const std::string& text);

/// Integrator choice and its settings.
struct IntegratorSettings {
  std::string name = "birkhoff_gauss4";  ///< a name from integrator_names(); the default scene's
  double step_size = 0.01;               ///< h [s], the default scene's
  double tolerance = 1e-10;              ///< dopri5 absolute and relative local tolerance [-] (dopri5 only)
  BirkhoffianForm birkhoffian_form = BirkhoffianForm::kAutonomous;
  int max_newton_iterations = 30;        ///< per implicit step
  double newton_tolerance = 1e-14;       ///< on the scaled Newton update [-]
  bool compensated_summation = true;     ///< Birkhoffian members: Kahan/TwoSum state update
  bool local_error_estimate = true;      ///< Birkhoffian members: compute ê (one more rhs evaluation a step)
  /// kFixed: steps of step_size. kReversible (symmetric Birkhoffian members): internal steps chosen
  /// by the reversible controller (docs/birkhoffian.md §11) for `position_tolerance`, the position
  /// error [m] the run may reach by `tolerance_horizon`; step_size is then only the output step.
  StepControl step_control = StepControl::kFixed;
  double position_tolerance = 0.0;  ///< reversible: the position error allowed at the horizon [m]; 0: not given
  double tolerance_horizon = 0.0;   ///< reversible: the time position_tolerance is for [s]; 0: the scene's duration
  /// kAdaptive (the Gauss members): estimate the position error the run gathers by a Richardson
  /// shadow run on doubled steps (docs/accuracy.md §4.5); up to half the work again, same steps.
  bool global_error_estimate = false;
};

/// The one check of a step control's tolerance: std::invalid_argument naming the setting when
/// position_tolerance [m] or tolerance_horizon [s] is not finite and > 0 ("step_control 'adaptive'
/// needs a finite position_tolerance > 0 m, got 0.000000"). `control`: the control's text.
void require_position_tolerance(const IntegratorSettings& settings, const std::string& control);

/// τ = position_tolerance / tolerance_horizon [1/s] (eq. (B.48)): the error per unit step that step
/// control `control` ("adaptive", "reversible") allows, after require_position_tolerance.
double error_per_unit_step(const IntegratorSettings& settings, const std::string& control);

}  // namespace birkhoff_cart

// The texts of the Birkhoffian forms and step controls (integrator_settings.h): one spelling table
// per enum, read both ways; the check of a step control's tolerance.
#include "birkhoff_cart/core/integrators/integrator_settings.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "birkhoff_cart/core/support/closest_name.h"

namespace birkhoff_cart {
namespace {

template <class Enum>
using Spelling = std::pair<Enum, const char*>;

const Spelling<BirkhoffianForm> kFormSpellings[] = {{BirkhoffianForm::kAutonomous, "autonomous"},
                                                    {BirkhoffianForm::kPaper, "paper"}};
const Spelling<StepControl> kControlSpellings[] = {{StepControl::kFixed, "fixed"},
                                                   {StepControl::kReversible, "reversible"},
                                                   {StepControl::kAdaptive, "adaptive"}};

template <class Enum, std::size_t N>
const char* text_of(Enum value, const Spelling<Enum> (&spellings)[N]) {
  for (const auto& [candidate, text] : spellings) {
    if (candidate == value) return text;
  }
  // Only a value cast from outside the enum gets here.
  throw std::invalid_argument("no text for enum value " + std::to_string(static_cast<int>(value)));
}

template <class Enum, std::size_t N>
std::vector<std::string> texts_of(const Spelling<Enum> (&spellings)[N]) {
  std::vector<std::string> texts;
  for (const auto& spelling : spellings) texts.emplace_back(spelling.second);
  return texts;
}

template <class Enum, std::size_t N>
Enum parse(const std::string& what, const std::string& text, const Spelling<Enum> (&spellings)[N]) {
  for (const auto& [value, candidate] : spellings) {
    if (text == candidate) return value;
  }
  throw std::invalid_argument(unknown_name_message(what, text, texts_of(spellings)));
}

}  // namespace

const char* to_string(BirkhoffianForm form) { return text_of(form, kFormSpellings); }
const char* to_string(StepControl control) { return text_of(control, kControlSpellings); }

const std::vector<std::string>& birkhoffian_form_names() {
  static const std::vector<std::string> kNames = texts_of(kFormSpellings);
  return kNames;
}
const std::vector<std::string>& step_control_names() {
  static const std::vector<std::string> kNames = texts_of(kControlSpellings);
  return kNames;
}

BirkhoffianForm parse_birkhoffian_form(const std::string& text) {
  return parse("birkhoffian_form", text, kFormSpellings);
}
StepControl parse_step_control(const std::string& text) { return parse("step_control", text, kControlSpellings); }

void require_position_tolerance(const IntegratorSettings& settings, const std::string& control) {
  if (!(settings.position_tolerance > 0.0) || !std::isfinite(settings.position_tolerance)) {
    throw std::invalid_argument("step_control '" + control + "' needs a finite position_tolerance > 0 m, got " +
                                std::to_string(settings.position_tolerance));
  }
  if (!(settings.tolerance_horizon > 0.0) || !std::isfinite(settings.tolerance_horizon)) {
    throw std::invalid_argument("integrator.tolerance_horizon must be finite and > 0 s");
  }
}

double error_per_unit_step(const IntegratorSettings& settings, const std::string& control) {
  require_position_tolerance(settings, control);
  return settings.position_tolerance / settings.tolerance_horizon;
}

}  // namespace birkhoff_cart

// load_scene: YAML scene file → validated Scene. Schema: docs/scenes.md.
#include "birkhoff_cart/core/scene/scene.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/support/closest_name.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/integrators/adaptive_refusal.h"
#include "birkhoff_cart/core/scene/step_schedule.h"
#include "scene_reader.h"

namespace birkhoff_cart {
namespace {

using scene_detail::Range;
using scene_detail::SceneReader;

/// The integrator registry's names: one list for the loader and for make_cart_stepper.
const std::vector<std::string>& known_integrators() {
  static const std::vector<std::string> kNames = integrator_names();
  return kNames;
}

/// `text` with every control character (line breaks, tabs, form feeds, ...) made a space: a
/// SceneError's message is one line even when a key or value from the file holds such bytes.
std::string one_line(std::string text) {
  for (char& character : text) {
    const unsigned char code = static_cast<unsigned char>(character);
    if (code < 0x20 || code == 0x7f) character = ' ';
  }
  return text;
}

std::string file_stem(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos ? name : name.substr(0, dot);
}

CartParameters read_cart(const SceneReader& reader, const YAML::Node& node) {
  CartParameters cart;
  const std::pair<const char*, double*> fields[] = {
      {"wheelbase", &cart.wheelbase},
      {"rear_half_track", &cart.rear_half_track},
      {"front_half_track", &cart.front_half_track},
      {"rear_wheel_radius", &cart.rear_wheel_radius},
      {"front_wheel_radius", &cart.front_wheel_radius},
      {"rear_body_mass", &cart.rear_body_mass},
      {"rear_body_yaw_inertia", &cart.rear_body_yaw_inertia},
      {"front_axle_mass", &cart.front_axle_mass},
      {"front_axle_yaw_inertia", &cart.front_axle_yaw_inertia},
      {"rear_wheel_mass", &cart.rear_wheel_mass},
      {"rear_wheel_spin_inertia", &cart.rear_wheel_spin_inertia},
      {"rear_wheel_yaw_inertia", &cart.rear_wheel_yaw_inertia},
      {"front_wheel_mass", &cart.front_wheel_mass},
      {"front_wheel_spin_inertia", &cart.front_wheel_spin_inertia},
      {"front_wheel_yaw_inertia", &cart.front_wheel_yaw_inertia},
      {"gravity", &cart.gravity},
  };
  std::vector<std::string> allowed;
  for (const auto& field : fields) allowed.push_back(field.first);
  reader.require_map(node, "cart", allowed);
  for (const auto& [name, destination] : fields) {
    *destination = reader.required_number(node, "cart", name, Range::kPositive);
  }
  return cart;
}

CartState read_initial_state(const SceneReader& reader, const YAML::Node& node) {
  const std::string key = "initial_state";
  reader.require_map(node, key,
                     {"time", "x", "y", "heading", "steering_angle", "wheel_spin_angles", "arc_length",
                      "forward_speed", "steering_rate"});
  CartState state;
  state.time = reader.optional_number(node, key, "time", Range::kFinite, 0.0);
  state.x = reader.optional_number(node, key, "x", Range::kFinite, 0.0);
  state.y = reader.optional_number(node, key, "y", Range::kFinite, 0.0);
  state.heading = reader.optional_number(node, key, "heading", Range::kFinite, 0.0);
  state.steering_angle = reader.required_number(node, key, "steering_angle", Range::kFinite);
  state.arc_length = reader.optional_number(node, key, "arc_length", Range::kFinite, 0.0);
  state.forward_speed = reader.required_number(node, key, "forward_speed", Range::kFinite);
  state.steering_rate = reader.required_number(node, key, "steering_rate", Range::kFinite);
  if (reader.has(node, "wheel_spin_angles")) {
    const std::string spin_key = SceneReader::join(key, "wheel_spin_angles");
    const YAML::Node spins = reader.required(node, key, "wheel_spin_angles");
    if (!spins.IsSequence() || spins.size() != 4) reader.fail(spin_key, "must be a list of 4 angles [rad]");
    for (std::size_t wheel = 0; wheel < 4; ++wheel) {
      state.wheel_spin_angle[wheel] =
          reader.number(spins[wheel], spin_key + "[" + std::to_string(wheel) + "]", Range::kFinite);
    }
  }
  return state;
}

IntegratorSettings read_integrator(const SceneReader& reader, const YAML::Node& node, const std::string& key) {
  reader.require_map(node, key,
                     {"name", "step_size", "tolerance", "birkhoffian_form", "max_newton_iterations",
                      "newton_tolerance", "compensated_summation", "local_error_estimate", "step_control",
                      "position_tolerance", "tolerance_horizon", "global_error_estimate"});
  IntegratorSettings settings;
  settings.name = reader.choice(node, key, "name", known_integrators());
  settings.step_size = reader.required_number(node, key, "step_size", Range::kPositive);
  settings.tolerance = reader.optional_number(node, key, "tolerance", Range::kPositive, settings.tolerance);
  if (reader.has(node, "birkhoffian_form")) {
    settings.birkhoffian_form =
        parse_birkhoffian_form(reader.choice(node, key, "birkhoffian_form", birkhoffian_form_names()));
  }
  settings.max_newton_iterations =
      reader.optional_positive_integer(node, key, "max_newton_iterations", settings.max_newton_iterations);
  settings.newton_tolerance =
      reader.optional_number(node, key, "newton_tolerance", Range::kPositive, settings.newton_tolerance);
  settings.compensated_summation =
      reader.optional_boolean(node, key, "compensated_summation", settings.compensated_summation);
  settings.local_error_estimate =
      reader.optional_boolean(node, key, "local_error_estimate", settings.local_error_estimate);
  if (reader.has(node, "step_control")) {
    settings.step_control = parse_step_control(reader.choice(node, key, "step_control", step_control_names()));
  }
  settings.position_tolerance =
      reader.optional_number(node, key, "position_tolerance", Range::kPositive, settings.position_tolerance);
  settings.tolerance_horizon =
      reader.optional_number(node, key, "tolerance_horizon", Range::kPositive, settings.tolerance_horizon);
  settings.global_error_estimate =
      reader.optional_boolean(node, key, "global_error_estimate", settings.global_error_estimate);
  if (settings.global_error_estimate && settings.step_control != StepControl::kAdaptive) {
    reader.fail(key + ".global_error_estimate", "is only for 'step_control: adaptive'");
  }
  if (settings.global_error_estimate && integrator_entry(settings.name).takes_tolerance()) {
    reader.fail(key + ".global_error_estimate", "is for the Gauss members, not '" + settings.name +
                                                    "' (a shadow on doubled steps needs the member's own grid)");
  }
  // One meaning per key: `tolerance` is dopri5's local tolerance [-] (kept in the shipped scenes for a
  // switch to dopri5), `position_tolerance` the position error [m] a step control aims at.
  if (settings.step_control != StepControl::kFixed) {
    const std::string control = to_string(settings.step_control);
    const bool offered = settings.step_control == StepControl::kReversible ? integrator_entry(settings.name).reversible()
                                                                           : integrator_entry(settings.name).adaptive();
    if (!offered && settings.step_control == StepControl::kReversible) {
      reader.fail(key + ".step_control", "'" + control + "' is for the symmetric Birkhoffian members (" +
                                             name_list(reversible_integrator_names()) + "), not '" + settings.name + "'");
    }
    if (!offered) {
      const std::string refusal = adaptive_refusal_message(settings.name);
      reader.fail(key + ".step_control", refusal.substr(refusal.find('\'')));  // "'adaptive' is for (…), not …"
    }
    if (!reader.has(node, "position_tolerance")) {
      reader.fail(key + ".position_tolerance", "is required with 'step_control: " + control +
                                               "': the position error [m] allowed at the horizon (" + key +
                                               ".tolerance is dopri5's local tolerance [-], not this)");
    }
  } else {
    for (const char* controlled_only : {"position_tolerance", "tolerance_horizon"}) {
      if (reader.has(node, controlled_only)) {
        reader.fail(key + "." + controlled_only, "is only for 'step_control: reversible' or 'adaptive'");
      }
    }
  }
  return settings;
}

ReferenceSettings read_reference(const SceneReader& reader, const YAML::Node& node, bool paper_special_case) {
  ReferenceSettings reference;
  if (!node || node.IsNull()) return reference;
  reader.require_map(node, "reference", {"kind", "integrator"});
  const std::string kind = reader.choice(node, "reference", "kind", {"none", "paper_analytic", "shadow_run"});
  if (kind == "shadow_run") {
    reference.kind = ReferenceSettings::Kind::kShadowRun;
    reference.shadow = read_integrator(reader, reader.required(node, "reference", "integrator"), "reference.integrator");
    if (reference.shadow.step_control != StepControl::kFixed) {
      reader.fail("reference.integrator.step_control", "must be 'fixed' (the shadow run is a dense dopri5 or a fixed step)");
    }
  } else {
    if (reader.has(node, "integrator")) reader.fail("reference.integrator", "is only for kind 'shadow_run'");
    if (kind == "paper_analytic") {
      if (!paper_special_case) {
        reader.fail("reference.kind", "'paper_analytic' needs 'paper_special_case: true' (the closed form of eq. (3.9))");
      }
      reference.kind = ReferenceSettings::Kind::kPaperAnalytic;
    }
  }
  return reference;
}

Scene read_scene(const SceneReader& reader, const YAML::Node& root, const std::string& path) {
  if (!root || root.IsNull()) reader.fail("(document)", "is empty");
  reader.require_map(root, "",
                     {"description", "cart", "paper_special_case", "initial_state", "duration", "integrator",
                      "output_rate", "effects", "reference", "accuracy", "odometry_sensor", "steering_actuator",
                      "drive_actuator", "steering_end_stops"});
  Scene scene;
  scene.name = file_stem(path);
  scene.source_path = path;
  scene.description = reader.text(reader.required(root, "", "description"), "description");
  if (scene.description.empty() || scene.description.find('\n') != std::string::npos) {
    reader.fail("description", "must be one non-empty line");
  }
  scene.cart = read_cart(reader, reader.required(root, "", "cart"));
  scene.paper_special_case = reader.optional_boolean(root, "", "paper_special_case", false);
  scene.initial_state = read_initial_state(reader, reader.required(root, "", "initial_state"));
  scene.duration = reader.required_number(root, "", "duration", Range::kPositive);
  scene.integrator = read_integrator(reader, reader.required(root, "", "integrator"), "integrator");
  if (scene.integrator.step_size > scene.duration) {
    reader.fail("integrator.step_size", "must not exceed the duration");
  }
  scene.output_rate = reader.optional_number(root, "", "output_rate", Range::kPositive, scene.output_rate);
  try {  // the scene time limits of step_schedule.h (start, end and resolution of t + h)
    plan_steps(scene.initial_state.time, scene.duration, scene.integrator.step_size);
  } catch (const TimeLimitError& error) {
    reader.fail(error.key(), error.problem());
  }
  scene.effects = scene_detail::read_effects(reader, root["effects"]);
  scene.reference = read_reference(reader, root["reference"], scene.paper_special_case);
  scene.accuracy = scene_detail::read_accuracy(reader, root["accuracy"]);
  scene.odometry_sensor = scene_detail::read_odometry_sensor(reader, root["odometry_sensor"]);
  scene.actuators = scene_detail::read_actuators(reader, root);
  if (scene.actuators.any() && scene.integrator.step_control != StepControl::kFixed) {
    reader.fail("integrator.step_control", std::string(to_string(scene.integrator.step_control)) +
                                               " cannot go with steering_actuator, drive_actuator or "
                                               "steering_end_stops (docs/actuators.md §4); use fixed");
  }
  if (scene.actuators.end_stops) {
    if (scene.paper_special_case) {
      reader.fail("steering_end_stops", "cannot go with paper_special_case: its M11 = mu + mu1 sin^2(chi) is 0, so an "
                                        "impact and the holding reaction (docs/actuators.md (S1), (S2)) are undefined");
    }
    if (scene.reference.kind == ReferenceSettings::Kind::kPaperAnalytic) {
      reader.fail("steering_end_stops", "cannot go with reference paper_analytic (its closed form has no stops); use "
                                        "shadow_run or none");
    }
    if (std::abs(scene.initial_state.steering_angle) > scene.actuators.end_stops->angle) {
      reader.fail("initial_state.steering_angle", "lies beyond the steering end stops at +-" +
                                                      std::to_string(scene.actuators.end_stops->angle) + " rad");
    }
  }

  // The cart must give a usable mass matrix (only the declared paper case may be singular).
  if (scene.paper_special_case && scene.cart.wheelbase != 1.0) {
    reader.fail("cart.wheelbase", "must be 1 with 'paper_special_case: true' (eq. (3.9) sets l = 1)");
  }
  try {
    const CartModel model(scene.cart, scene.paper_special_case ? InertiaModel::kPaperSpecialCase
                                                               : InertiaModel::kPhysical);
    // the effects accept their coefficients, the actuators their inputs
    build_effects(scene.effects, model, scene.actuators, scene.initial_state.time);
  } catch (const SceneError&) {
    throw;
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    std::string key = "cart";
    for (const char* section : {"effect", "steering_actuator", "drive_actuator", "steering_end_stops"}) {
      if (message.rfind(section, 0) == 0) key = std::string(section) == "effect" ? "effects" : section;
    }
    reader.fail(key, one_line(message));
  }
  return scene;
}

}  // namespace

SceneError::SceneError(const std::string& file, const std::string& key, const std::string& problem)
    : std::runtime_error(one_line("scene " + file + ": key '" + key + "': " + problem)), file_(file), key_(key) {}

namespace {

/// Parses `text` as YAML, within the bounds of check_scene_structure, and reads the scene, naming
/// `source` in every SceneError.
Scene parse_scene(const std::string& text, const std::string& source) {
  const SceneReader reader(source);
  YAML::Node root;
  try {
    scene_detail::check_scene_structure(reader, text);
    root = YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    reader.fail("(syntax)", "YAML syntax error at line " + std::to_string(error.mark.line + 1) + ", column " +
                                std::to_string(error.mark.column + 1) + ": " + error.msg);
  }
  try {
    return read_scene(reader, root, source);
  } catch (const SceneError&) {
    throw;
  } catch (const YAML::Exception& error) {
    reader.fail("(document)", one_line(error.what()));
  }
}

}  // namespace

Scene load_scene(const std::string& path) { return parse_scene(read_scene_file(path), path); }

Scene load_scene_text(const std::string& text, const std::string& source) { return parse_scene(text, source); }

}  // namespace birkhoff_cart

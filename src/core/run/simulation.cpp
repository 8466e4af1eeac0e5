#include "birkhoff_cart/core/run/simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "birkhoff_cart/core/physics/actuators/steering_end_stops.h"
#include "birkhoff_cart/core/physics/actuators/torque_actuator.h"
#include "birkhoff_cart/core/physics/effect_library.h"
#include "birkhoff_cart/core/run/accuracy_floors.h"
#include "birkhoff_cart/core/run/reference_solution.h"
#include "birkhoff_cart/core/physics/restart_state.h"
#include "birkhoff_cart/core/physics/singular_steering.h"

namespace birkhoff_cart {
namespace {

InertiaModel inertia_model_of(const Scene& scene) {
  return scene.paper_special_case ? InertiaModel::kPaperSpecialCase : InertiaModel::kPhysical;
}

/// The initial command value of the scene's command-sourced effect `name` [N·m] (0 if none).
double initial_command(const Scene& scene, const std::string& name) {
  for (const EffectSpec& spec : scene.effects) {
    if (spec.name == name && spec.profile.kind == TorqueProfile::Kind::kCommand) return spec.profile.value;
  }
  return 0.0;
}

void require_finite_torque(double torque, const char* which) {
  if (!std::isfinite(torque)) {
    std::ostringstream message;
    message << which << " command must be a finite torque [N·m], got " << torque;
    throw std::invalid_argument(message.str());
  }
}

/// The scene's integrator settings with the defaults that depend on the scene filled in: the
/// reversible controller's tolerance horizon is the scene's duration unless the scene names one.
/// Refuses the reversible control with actuators or end stops: its internal steps run ahead of the
/// step being committed, while the actuators' state and the end-stop events advance step by step
/// (docs/actuators.md §4).
IntegratorSettings integrator_settings(const Scene& scene) {
  if (scene.actuators.any() && scene.integrator.step_control != StepControl::kFixed) {
    throw std::invalid_argument(std::string("integrator.step_control: ") + to_string(scene.integrator.step_control) +
                                " cannot go with steering_actuator, drive_actuator or steering_end_stops "
                                "(docs/actuators.md); use fixed");
  }
  IntegratorSettings settings = scene.integrator;
  if (settings.tolerance_horizon == 0.0) settings.tolerance_horizon = scene.duration;
  const double floor = position_tolerance_floor(scene);  // [m]
  if (settings.step_control != StepControl::kFixed && settings.position_tolerance > 0.0 &&
      settings.position_tolerance < floor) {
    std::ostringstream message;
    message << "integrator.position_tolerance " << settings.position_tolerance << " m is below what double precision "
            << "reaches on this scene: " << floor << " m (1000 machine epsilons times its length scale; "
            << "docs/accuracy.md)";
    throw std::invalid_argument(message.str());
  }
  return settings;
}

}  // namespace

double scene_length_scale(const Scene& scene) {
  const CartState& start = scene.initial_state;
  const double travel = std::abs(start.forward_speed) * scene.duration;  // [m]
  return std::max({1.0, scene.cart.wheelbase, std::abs(start.x), std::abs(start.y), travel});
}

double position_tolerance_floor(const Scene& scene) {
  return 1000.0 * std::numeric_limits<double>::epsilon() * scene_length_scale(scene);
}

double shadow_reference_resolution(const Scene& scene) {
  const ReferenceSettings& reference = scene.reference;
  if (reference.kind != ReferenceSettings::Kind::kShadowRun || reference.shadow.name != "dopri5") return 0.0;
  return 100.0 * reference.shadow.tolerance * scene_length_scale(scene);
}

Simulation::Simulation(const Scene& scene)
    : scene_(scene),
      model_(scene.cart, inertia_model_of(scene)),
      effects_(build_effects(scene.effects, model_, scene.actuators, scene.initial_state.time)),
      stepper_(make_cart_stepper(integrator_settings(scene), model_, effects_)),
      state_(scene.initial_state),
      schedule_(plan_steps(scene.initial_state.time, scene.duration, scene.integrator.step_size)),
      loaded_initial_state_(scene.initial_state) {
  stepper_->prepare(state_, statistics_);  // the reversible control's pilots; refuses an unreachable tolerance
  stepper_->land_on(schedule_.end_time);    // a step control lands on the run's end
  initial_energy_ = model_.energy(state_);
  initial_steering_momentum_ = model_.steering_momentum(state_);
  reference_ = make_reference_solution(scene_, model_, effects_);
}

Simulation::~Simulation() = default;

double Simulation::end_time() const {
  return endless_ ? std::numeric_limits<double>::infinity() : schedule_.end_time;
}

void Simulation::plan_run(double duration) {
  // step() lands on t₀ + n h counted from the run's start; a plan from the current time is on the
  // same grid only at step 0.
  if (steps_taken_ != 0) {
    throw std::logic_error("scene '" + scene_.name + "': a run is planned only at its start (" +
                           std::to_string(steps_taken_) + " steps taken)");
  }
  if (std::isinf(duration) && duration > 0.0) {
    endless_ = true;
    return;
  }
  const StepSchedule schedule = plan_steps(state_.time, duration, scene_.integrator.step_size);
  schedule_ = schedule;
  endless_ = false;
  stepper_->land_on(schedule_.end_time);
}

double Simulation::next_step_time() const {
  if (!endless_ && steps_taken_ >= schedule_.whole_steps) return schedule_.end_time;
  return state_.time + scene_.integrator.step_size;
}

void Simulation::step() {
  if (controlled_off_grid_) {
    throw std::logic_error("scene '" + scene_.name + "': advance_output_to() took this run off the step grid; " +
                           "continue with advance_output_to() or reset()");
  }
  if (finished_off_grid_) {
    throw std::logic_error("scene '" + scene_.name + "' already ended off the step grid at t = " +
                           std::to_string(state_.time) + " s; reset() before stepping again");
  }
  const double h = scene_.integrator.step_size;  // [s]
  // tₙ₊₁ = t₀ + (n+1) h exactly, not an accumulated sum of h.
  take_step(h, scene_.initial_state.time + static_cast<double>(steps_taken_ + 1) * h);
}

void Simulation::step_on_schedule() {
  if (at_end()) {
    throw std::logic_error("scene '" + scene_.name + "' is already at its end t = " + std::to_string(state_.time) +
                           " s; reset() before stepping again");
  }
  if (endless_ || steps_taken_ < schedule_.whole_steps) step();
  else step_to(schedule_.end_time);
}

namespace {

/// Refuses (std::invalid_argument, naming `call`) a step from t_n = `from` to `time` [s] that is not
/// 0 < time − t_n ≤ (1 + 2·kMinFinalStepFraction) h: one step, a schedule's final one included.
void require_one_step(const char* call, double from, double time, double step_size) {
  const double longest = step_size * (1.0 + 2.0 * kMinFinalStepFraction);  // [s]
  if (std::isfinite(time) && time - from > 0.0 && time - from <= longest) return;
  std::ostringstream message;
  message.precision(17);
  message << call << "(" << time << " s) from t = " << from << " s needs 0 < t - t_n <= (1 + 2e-5) h = " << longest
          << " s";
  throw std::invalid_argument(message.str());
}

}  // namespace

void Simulation::step_to(double time) {
  if (controlled_off_grid_) {
    throw std::logic_error("scene '" + scene_.name + "': advance_output_to() took this run off the step grid; " +
                           "continue with advance_output_to() or reset()");
  }
  require_one_step("step_to", state_.time, time, scene_.integrator.step_size);
  take_step(time - state_.time, time);
  finished_off_grid_ = true;
}

void Simulation::take_step(double h, double next_time) {
  if (effects_.steering_actuator() || effects_.drive_actuator() || effects_.end_stops()) {
    take_step_with_events(next_time);
    return;
  }
  CartState next = state_;
  StepStatistics statistics = statistics_;
  check_singular_steering(model_, state_, h);  // paper case: refuse a step onto χ = kπ (docs/hard_cases.md §1)
  stepper_->step(next, h, statistics);         // throws StepError; `next` is then discarded
  check_singular_steering(model_, state_, h, &next);
  next.time = next_time;
  if (reference_) reference_->step(next.time);  // transactional itself; throws before we commit
  state_ = next;
  statistics_ = statistics;
  ++steps_taken_;
}

bool Simulation::takes_own_steps() const {
  return scene_.integrator.step_control != StepControl::kFixed || integrator_entry(scene_.integrator.name).takes_tolerance();
}

void Simulation::advance_output_to(double time) {
  if (!takes_own_steps()) {
    throw std::logic_error("scene '" + scene_.name + "': advance_output_to() is for a member with its own steps (a "
                           "step control, or dopri5); " + scene_.integrator.name + " steps at fixed steps of h");
  }
  const double end = end_time();
  if (!std::isfinite(time) || !(time > state_.time) || time > end) {
    std::ostringstream message;
    message.precision(17);
    message << "advance_output_to(" << time << " s) from t = " << state_.time << " s needs t < time <= the end "
            << end << " s";
    throw std::invalid_argument(message.str());
  }
  take_step(time - state_.time, time);
  controlled_off_grid_ = true;
  if (!endless_ && time == end) steps_taken_ = schedule_.total_steps();  // at_end()
}

CartState Simulation::state_by_one_step(const CartState& from, double time, StepStatistics* work) const {
  if (takes_own_steps()) {
    throw std::logic_error("state_by_one_step() is for a member at fixed steps; " + scene_.integrator.name +
                           " takes its own steps: read its dense output (newest_step_state)");
  }
  if (effects_.steering_actuator() || effects_.drive_actuator() || effects_.end_stops()) {
    throw std::logic_error("scene '" + scene_.name + "': state_by_one_step() cannot step beside the run: its "
                           "actuators or end stops have a state of their own that moves with the run's steps");
  }
  require_one_step("state_by_one_step", from.time, time, scene_.integrator.step_size);
  const double length = time - from.time;  // [s]
  if (!one_step_stepper_) one_step_stepper_ = make_cart_stepper(integrator_settings(scene_), model_, effects_);
  CartState next = from;
  StepStatistics uncounted;
  one_step_stepper_->step(next, length, work ? *work : uncounted);
  next.time = time;
  return next;
}

void Simulation::observe_grid(CartStepper::GridObserver observer) {
  grid_observer_ = std::move(observer);
  stepper_->observe_grid(grid_observer_);
}

void Simulation::advance_to(double time) {
  const double h = scene_.integrator.step_size;
  while (state_.time + 0.5 * h <= time) step();
}

void Simulation::reset() {
  Scene loaded = scene_;
  loaded.initial_state = loaded_initial_state_;  // also after restart_from(): the loaded scene's start
  start_actuators(effects_, loaded.effects, loaded.initial_state.time);  // before the pilots of start_run
  start_run(std::move(loaded));
  if (effects_.steering_command()) effects_.steering_command()->value = initial_command(scene_, "steering_torque");
  if (effects_.drive_command()) effects_.drive_command()->value = initial_command(scene_, "drive_torque");
}

void Simulation::restart_from(const CartState& initial_state) {
  check_restart_state(model_, effects_, initial_state, scene_.integrator.step_size);
  Scene restarted = scene_;
  restarted.initial_state = initial_state;
  // The balances' integrals run from the run's start (docs eq. (3.7), (3.8)): a restart is one.
  restarted.initial_state.applied_work = 0.0;
  restarted.initial_state.steering_impulse = 0.0;
  check_trial_step(restarted);
  start_run(std::move(restarted));
  // The actuators keep their torques and pending inputs (a teleport moves the cart, not its motors).
  if (effects_.steering_actuator()) effects_.steering_actuator()->retime(scene_.initial_state.time);
  if (effects_.drive_actuator()) effects_.drive_actuator()->retime(scene_.initial_state.time);
  if (effects_.end_stops()) effects_.end_stops()->set_contact(SteeringEndStops::Contact::kNone);
}

void Simulation::check_trial_step(const Scene& run_scene) {
  // The run's own stepper starts fresh (start_run): the trial has one of its own. End stops take
  // no contact from the state before (as after the commit below).
  SteeringEndStops* const stops = effects_.end_stops().get();
  const SteeringEndStops::Contact contact = stops ? stops->contact() : SteeringEndStops::Contact::kNone;
  if (stops) stops->set_contact(SteeringEndStops::Contact::kNone);
  const double h = run_scene.integrator.step_size;  // [s]
  std::string failure;
  try {
    std::unique_ptr<CartStepper> stepper = make_cart_stepper(integrator_settings(run_scene), model_, effects_);
    StepStatistics statistics;
    const CartState& start = run_scene.initial_state;
    stepper->prepare(start, statistics);
    CartState next = start;
    stepper->step(next, h, statistics);
    check_singular_steering(model_, start, h, &next);
    const double energy = model_.energy(next);  // [J]
    if (!std::isfinite(energy)) failure = "its kinetic energy T* becomes " + std::to_string(energy) + " J";
  } catch (const StepError& error) {
    failure = error.what();
  } catch (...) {
    if (stops) stops->set_contact(contact);
    throw;
  }
  if (stops) stops->set_contact(contact);
  if (!failure.empty()) {
    std::ostringstream message;
    message << "restart state: a trial step of h = " << h << " s from it fails: " << failure;
    throw std::invalid_argument(message.str());
  }
}

void Simulation::start_run(Scene run_scene) {
  // Everything that can refuse is built before anything changes.
  const CartState& start = run_scene.initial_state;
  StepSchedule schedule = plan_steps(start.time, run_scene.duration, run_scene.integrator.step_size);
  std::unique_ptr<ReferenceSolution> reference = make_reference_solution(run_scene, model_, effects_);
  // A new stepper forgets the step memory (adaptive step-size guesses, the stage predictor).
  std::unique_ptr<CartStepper> stepper = make_cart_stepper(integrator_settings(run_scene), model_, effects_);
  StepStatistics statistics;
  CartState state = start;
  stepper->prepare(state, statistics);  // the reversible control's pilots may refuse the state
  stepper->land_on(schedule.end_time);
  // Commit: nothing below throws.
  scene_ = std::move(run_scene);
  schedule_ = schedule;
  endless_ = false;
  reference_ = std::move(reference);
  stepper_ = std::move(stepper);
  state_ = state;
  statistics_ = statistics;
  steps_taken_ = 0;
  end_stop_events_ = 0;
  finished_off_grid_ = false;
  controlled_off_grid_ = false;
  stepper_->observe_grid(grid_observer_);
  initial_energy_ = model_.energy(state_);
  initial_steering_momentum_ = model_.steering_momentum(state_);
}

void Simulation::land_on(double time) { stepper_->land_on(time); }

bool Simulation::accepts_steering_command() const { return static_cast<bool>(effects_.steering_command()); }
bool Simulation::accepts_drive_command() const { return static_cast<bool>(effects_.drive_command()); }

void Simulation::set_steering_command(double torque) {
  if (!accepts_steering_command()) {
    throw std::logic_error("scene '" + scene_.name + "' has no steering_torque effect with source 'command'");
  }
  require_finite_torque(torque, "steering");
  if (reference_ && effects_.steering_command()->value != torque) reference_->command_changes(state_.time);
  if (effects_.steering_actuator()) effects_.steering_actuator()->command(state_.time, torque);
  effects_.steering_command()->value = torque;
}

void Simulation::set_drive_command(double torque) {
  if (!accepts_drive_command()) {
    throw std::logic_error("scene '" + scene_.name + "' has no drive_torque effect with source 'command'");
  }
  require_finite_torque(torque, "drive");
  if (reference_ && effects_.drive_command()->value != torque) reference_->command_changes(state_.time);
  if (effects_.drive_actuator()) effects_.drive_actuator()->command(state_.time, torque);
  effects_.drive_command()->value = torque;
}

double Simulation::steering_command() const {
  return effects_.steering_command() ? effects_.steering_command()->value : 0.0;
}

double Simulation::drive_command() const { return effects_.drive_command() ? effects_.drive_command()->value : 0.0; }

Diagnostics Simulation::diagnostics() const {
  Diagnostics diagnostics = balances_of(state_);
  if (reference_) reference_->compare(state_, diagnostics);
  return diagnostics;
}

Diagnostics Simulation::balances_of(const CartState& state) const {
  Diagnostics diagnostics;
  diagnostics.energy = model_.energy(state);
  // T* − T*₀ − ∫ω·Q dt (docs eq. (3.7)) and p2 − p2₀ − ∫Q2 dt (docs eq. (3.8))
  diagnostics.energy_balance_residual = diagnostics.energy - initial_energy_ - state.applied_work;
  diagnostics.p2_balance_residual = model_.steering_momentum(state) - initial_steering_momentum_ - state.steering_impulse;
  diagnostics.max_constraint_residual = model_.max_constraint_residual(state);
  return diagnostics;
}

}  // namespace birkhoff_cart

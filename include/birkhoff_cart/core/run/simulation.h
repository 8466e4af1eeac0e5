// A running scene: the constant model and effects, the chosen integrator, the mutable state and
// its diagnostics. The time loop belongs to the caller (CLI, node, benchmark): step() advances
// exactly one step of size h. Failures are transactional: a step that throws leaves the state
// exactly as it was.
//
// Where a run ends and how it is cut into steps is the rule of step_schedule.h, planned once at
// construction for the scene's t₀, duration and h (schedule()). The scene's whole run is
//   while (!simulation.at_end()) simulation.step_on_schedule();
// A caller with another end (the node's ~duration) plans it with plan_steps() and uses step() for
// the whole steps and step_to(end) for the final one.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "birkhoff_cart/core/physics/cart_model.h"
#include "birkhoff_cart/core/integrators/diagnostics.h"
#include "birkhoff_cart/core/physics/effects.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/physics/state.h"
#include "birkhoff_cart/core/scene/step_schedule.h"

namespace birkhoff_cart {

class Simulation {
 public:
  /// Builds model, effects and integrator from a validated scene. Throws std::invalid_argument
  /// naming the problem (unknown integrator, degenerate mass matrix, ...); TimeLimitError (an
  /// std::invalid_argument) when t₀, duration or h break a limit of step_schedule.h.
  explicit Simulation(const Scene& scene);
  ~Simulation();

  const Scene& scene() const { return scene_; }
  const CartModel& model() const { return model_; }
  const EffectSet& effects() const { return effects_; }
  const CartState& state() const { return state_; }
  /// Where the run ends [s]: the scene's t0 + duration, or what plan_run() set (+inf: without end).
  double end_time() const;
  /// False after plan_run(+inf): the run has no end, and schedule() does not apply.
  bool has_end() const { return !endless_; }
  /// How the run is cut into steps (plan_steps of t₀, duration, h; the scene's, or plan_run()'s).
  const StepSchedule& schedule() const { return schedule_; }
  /// Steps taken since construction or reset() (whole and final).
  std::uint64_t steps_taken() const { return steps_taken_; }
  /// True once the run's schedule is done: the state is at end_time() exactly (never without end).
  bool at_end() const { return !endless_ && steps_taken_ >= schedule_.total_steps(); }
  /// The next step of the run's schedule: step() while whole steps remain (always, without end),
  /// then step_to(end_time()) if the schedule has a final step. Throws std::logic_error when
  /// at_end(), StepError as step().
  void step_on_schedule();
  /// Where step_on_schedule() will land next [s]: end_time() for the final step, else t + h.
  double next_step_time() const;
  /// A run of `duration` [s] from the current time instead of the scene's (a node's own run length;
  /// the rest of a run after a teleport), cut by the rule of step_schedule.h; +inf: a run without
  /// end. Only at a run's start (steps_taken() == 0: after construction, reset(), restart_from(),
  /// which plan the scene's duration again). Throws std::logic_error after a step, TimeLimitError
  /// (key "duration") for a duration the rule refuses; nothing changes then.
  void plan_run(double duration);
  double step_size() const { return scene_.integrator.step_size; }
  const std::string& integrator_name() const { return scene_.integrator.name; }

  /// Advances one step of size h. The state's time is t0 + n h exactly (no accumulated round-off).
  /// Throws StepError (state unchanged) when the step fails (Newton did not converge, a
  /// non-finite value appeared, the mass matrix became singular).
  void step();
  /// Steps while time + h/2 ≤ `time`.
  void advance_to(double time);
  /// One final step of size time − t (0 < size ≤ (1 + 2·kMinFinalStepFraction) h: a schedule's final
  /// step may absorb a sliver) that lands exactly on `time`: for an end time
  /// off the step grid (the paper's case runs from π/2 to 3.0). Afterwards the run is over:
  /// step() throws std::logic_error until reset(). Throws std::invalid_argument for a bad time.
  void step_to(double time);
  /// Back to the scene's initial state, counters and reference included (also after restart_from():
  /// the loaded scene's state, time and schedule).
  void reset();
  /// A new run from `initial_state` at its own time t₀' (a teleport: the caller passes the current
  /// time to keep time continuous). Restarts like reset(): the step memory, the counters, the
  /// reference (rebuilt from the new state), the invariants' initial values and the balances'
  /// integrals (applied_work, steering_impulse start at 0); the schedule is
  /// t₀' + the scene's duration; commands keep their values. Refuses, leaving everything as it was,
  /// with std::invalid_argument naming the problem: a state that breaks check_restart_state()
  /// (non-finite, beyond the ranges a step resolves, a singular steering angle within the next step
  /// as in the paper's special case at χ = kπ, docs/hard_cases.md §1, beyond the end stops); a state
  /// from which a trial step fails (check_trial_step()); a reference that cannot start there
  /// (paper_analytic off its analytic state); a time beyond the limits of step_schedule.h.
  void restart_from(const CartState& initial_state);

  /// For a member with its own steps (integrator.step_control adaptive or reversible; dopri5, one
  /// run over the whole run): the state at `time` [s],
  /// any instant after the current one up to end_time(), however far (the control's own steps, and
  /// its dense output between them; the run's end and land_on() instants exactly). The output grid
  /// of such a run need not be a multiple of step_size(). After it, step() and step_on_schedule()
  /// refuse (the run left their grid); at_end() is true once `time` is end_time(). Throws
  /// std::logic_error for a member at fixed steps, std::invalid_argument for a time not ahead or past
  /// the end, StepError as step().
  void advance_output_to(double time);
  /// Does this run's member take its own steps (a step control; dopri5)?
  bool takes_own_steps() const;
  /// `observer` is called with the state after every accepted step of a step control's own grid
  /// (not for fixed-step members). Kept across reset() and restart_from(); an empty function stops it.
  void observe_grid(CartStepper::GridObserver observer);
  /// For a member with its own steps: the state at `time` [s] within its newest accepted own step,
  /// from its dense output, without moving the run (CartStepper::newest_step_state; a grid observer
  /// may call it for the step it is told of: event location). The evaluations it takes are added to
  /// `*work` when given, never to statistics(). False when there is none there.
  bool newest_step_state(double time, CartState& out, StepStatistics* work = nullptr) const {
    StepStatistics uncounted;
    return stepper_->newest_step_state(time, out, work ? *work : uncounted);
  }
  /// For a member at fixed steps: the state at `time` [s] reached by one step of the member from
  /// `from` (a state of this run, from.time < time ≤ from.time + h), by a stepper of its own: the
  /// state between two steps to the member's order, the run, its stepper's memory and its counters
  /// unmoved (event location at fixed steps); its work is added to `*work` when given. Throws
  /// std::logic_error for a member with its own steps (newest_step_state reads their dense output)
  /// and for a scene with actuators or end stops (their state moves with the run's steps);
  /// std::invalid_argument for a time outside (from.time, from.time + (1 + 2·kMinFinalStepFraction) h];
  /// StepError as a step.
  CartState state_by_one_step(const CartState& from, double time, StepStatistics* work = nullptr) const;

  /// An instant [s] a step control's own steps must end on exactly instead of interpolating there
  /// (CartStepper::land_on; the run's end always is one). For the current run only: reset() and
  /// restart_from() forget it. Fixed-step members ignore it.
  void land_on(double time);

  /// Command inputs (zero-order hold). Throw std::invalid_argument for a non-finite torque and
  /// std::logic_error when the scene's effect does not take commands.
  bool accepts_steering_command() const;
  bool accepts_drive_command() const;
  void set_steering_command(double torque);  ///< [N·m]
  void set_drive_command(double torque);     ///< [N·m]
  double steering_command() const;           ///< the torque in force [N·m]
  double drive_command() const;              ///< the torque in force [N·m]

  /// The actuators' and end stops' state (all zero/false when the scene enables none).
  struct ActuatorStatus {
    bool steering_actuator = false;     ///< the scene has a steering actuator
    double steering_input = 0.0;        ///< latest commanded steering torque [N·m]
    double steering_applied = 0.0;      ///< steering torque the hinge receives now [N·m]
    bool drive_actuator = false;        ///< the scene has a drive actuator
    double drive_input = 0.0;           ///< latest commanded drive torque [N·m]
    double drive_applied = 0.0;         ///< drive torque the rear axle receives now [N·m]
    bool end_stops = false;             ///< the scene has steering end stops
    int end_stop_contact = 0;           ///< +1 resting on +χ_s, −1 on −χ_s, 0 free
    std::uint64_t end_stop_events = 0;  ///< impacts and releases since the run's start [-]
  };
  ActuatorStatus actuator_status() const;

  /// Invariants and errors of the current state (reference error only when the scene asks).
  Diagnostics diagnostics() const;
  /// The energy and p2 balances and the constraint residual of `state`, a state of this run (a grid
  /// state seen by observe_grid): diagnostics() without the reference comparison.
  Diagnostics balances_of(const CartState& state) const;
  const StepStatistics& statistics() const { return statistics_; }

 private:
  Scene scene_;  ///< the run's scene: the loaded one, or with its restart_from() state
  CartModel model_;
  EffectSet effects_;
  std::unique_ptr<CartStepper> stepper_;
  CartState state_;
  StepSchedule schedule_;
  CartState loaded_initial_state_;  ///< the loaded scene's initial state, for reset()
  void take_step(double step_size, double next_time);
  /// take_step with actuators or end stops: ends sub-steps at the actuators' kinks and at end-stop
  /// events (docs/actuators.md §4).
  void take_step_with_events(double next_time);
  std::uint64_t end_stop_events_ = 0;
  /// A step of h from `run_scene`'s initial state with a stepper of its own; throws
  /// std::invalid_argument ("a trial step ... fails: ...") when it throws a StepError or ends with a
  /// non-finite energy. Changes nothing.
  void check_trial_step(const Scene& run_scene);
  /// Builds the schedule, reference and stepper of a run of `run_scene` from its initial state and
  /// commits them with zeroed counters and the invariants' initial values (reset(), restart_from()).
  /// Throws, with nothing changed, when the reference or the reversible control refuses the state.
  void start_run(Scene run_scene);

  std::uint64_t steps_taken_ = 0;
  bool finished_off_grid_ = false;  ///< step_to() left the grid t₀ + n h
  bool controlled_off_grid_ = false;  ///< advance_output_to() left the grid t₀ + n h
  CartStepper::GridObserver grid_observer_;
  mutable std::unique_ptr<CartStepper> one_step_stepper_;  ///< state_by_one_step's own, made when first asked
  bool endless_ = false;            ///< plan_run(+inf): no end, schedule_ unused
  StepStatistics statistics_;
  double initial_energy_ = 0.0;
  double initial_steering_momentum_ = 0.0;
  std::unique_ptr<class ReferenceSolution> reference_;
};

}  // namespace birkhoff_cart

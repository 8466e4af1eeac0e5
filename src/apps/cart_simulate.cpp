// cart_simulate: runs a scene in batch and writes the trajectory as CSV (no ROS master needed).
//
//   cart_simulate --scene FILE [--integrator NAME] [--step H] [--tolerance TOL] [--duration T]
//                 [--output-rate HZ] [--birkhoffian-form F] [--quiet] [--step-control C]
//                 [--position-tolerance M] [--on-accuracy-error fail|warn] [--random-scene SEED:K]
//                 [--event FIELD=VALUE[,rising|falling][,terminal]]... [--events-output FILE.csv]
//                 --output FILE.csv   (also --option=value)
//   cart_simulate --help | -h | --version
//   cart_simulate --list-integrators [--json]
//
// --list-integrators prints the registry's table (as --help shows it), or with --json one JSON
// object: {"integrators": [{"name", "order", "symmetric", "reversible", "vector_stages", "kind",
// "takes_tolerance", "description"}, ...] in the registry's order, "birkhoffian_forms": [...],
// "step_controls": [...]} (the study runner reads it: src/birkhoff_cart_study/registry.py).
//
// Columns: t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate (SI
// units; energy is T* [J], p2 the front axle's yaw momentum [kg·m²/s], local_error_estimate the
// last step's ê [-], empty when the integrator has none: docs/accuracy.md), and with the scene's
// odometry sensor on, odom_x,odom_y,odom_theta,odom_sigma_position,odom_sigma_theta (its estimate of
// A and θ, read at every row, and their standard deviations: docs/odometry_sensor.md), with its
// actuators steering_torque_applied, drive_torque_applied [N·m] and with its steering end stops
// end_stop_contact (+1 on +χ_s, −1 on −χ_s, 0 free: docs/actuators.md); one row per output
// instant t0 + k/HZ from the start to the end, both included; values printed with %.17g
// (round-trip exact). At the end a summary goes to stdout, with the accuracy guard's verdict
// (the scene's `accuracy` limits, checked at every row). The run is cut
// into steps by the rule of step_schedule.h (Simulation::step_on_schedule): the last row is at
// t0 + T exactly.
// Events (--event, repeatable; docs/events.md): each crossing of a state field through a value is
// located on the member's own step to 1e-12 s (state_events.h) and printed on stdout as a line
// "event NAME at t = … s: x = …" before the summary; a terminal one stops the run at the first step
// of the schedule that reached it (no row after its time; a line says so).
// Progress: a run longer than a second of wall time reports, at most once a second on stderr,
// the percentage of scene time done and the real-time factor (unless --quiet).
// Exit status: 0 done (also --help, --version); 2 bad arguments (usage on stderr); 3 unusable
// scene or settings (including the scene time limits), or the CSV cannot be written; 4 a step
// failed or the run stopped on an unexpected error (the rows written so far are flushed and kept);
// 5 the accuracy guard reached ERROR (all rows written; with --on-accuracy-error warn the run
// exits 0 and the summary still says ERROR).
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/support/csv_number.h"
#include "birkhoff_cart/core/scene/accuracy_guard.h"
#include "birkhoff_cart/core/support/closest_name.h"
#include "birkhoff_cart/core/cart_binding/cart_stepper.h"
#include "birkhoff_cart/core/cart_binding/integrator_registry.h"
#include "birkhoff_cart/core/run/guarded_run.h"
#include "birkhoff_cart/core/run/paper_form_drift.h"
#include "birkhoff_cart/core/run/run_summary.h"
#include "birkhoff_cart/core/run/random_scene.h"
#include "birkhoff_cart/core/scene/scene.h"
#include "birkhoff_cart/core/physics/sensors/odometry_sensor.h"
#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/run/state_events.h"
#include "birkhoff_cart/core/scene/step_schedule.h"
#include "birkhoff_cart/core/support/version.h"

namespace {

using birkhoff_cart::CartState;
using birkhoff_cart::Scene;
using birkhoff_cart::Simulation;

constexpr int kExitUsage = 2;
constexpr int kExitSettings = 3;
constexpr int kExitStepFailed = 4;
constexpr int kExitAccuracy = 5;
constexpr double kProgressPeriod = 1.0;  // at most one progress line per this much wall time [s]

/// `names` as "a|b" (a usage line), "a or b", "'a' or 'b'" (quoted), with ", " before the last.
std::string alternatives(const std::vector<std::string>& names, const std::string& separator,
                         const std::string& last_separator, const std::string& quote = "") {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? last_separator : separator;
    text += quote + names[i] + quote;
  }
  return text;
}

/// The registry's members, one line each: name, order, symmetric, takes the reversible control,
/// takes the adaptive control, evaluates its stages together, kind, scheme. The members that take --step-control reversible come first.
std::string integrator_table() {
  std::vector<birkhoff_cart::IntegratorEntry> members = birkhoff_cart::integrator_registry();
  std::stable_partition(members.begin(), members.end(),
                        [](const birkhoff_cart::IntegratorEntry& member) { return member.reversible(); });
  std::string table =
      "Integrators (--integrator NAME; docs/integrators.md). p: the order; symmetric: a time-symmetric\n"
      "step map; reversible, adaptive: takes --step-control reversible, adaptive; vector: evaluates its\n"
      "stages together, with one vector sin/cos where the CPU has AVX.\n"
      "  NAME                p  symmetric  reversible  adaptive  vector  kind                     scheme\n";
  for (const birkhoff_cart::IntegratorEntry& member : members) {
    char line[220];
    std::snprintf(line, sizeof line, "  %-19s %-2d %-10s %-11s %-9s %-7s %-24s %s\n", member.name, member.order,
                  member.symmetric ? "yes" : "no", member.reversible() ? "yes" : "no",
                  member.adaptive() ? "yes" : "no", member.vector_stages ? "yes" : "no",
                  birkhoff_cart::to_string(member.kind), member.description);
    table += line;
  }
  return table;
}

/// `text` as a JSON string (quotes, backslashes and control characters escaped).
std::string json_quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string json_list(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + json_quoted(names[i]);
  return out + "]";
}

/// The registry, the Birkhoffian forms and the step controls as one JSON object (--list-integrators --json).
std::string integrator_listing_json() {
  std::string out = "{\"integrators\": [";
  const std::vector<birkhoff_cart::IntegratorEntry>& members = birkhoff_cart::integrator_registry();
  for (std::size_t i = 0; i < members.size(); ++i) {
    const birkhoff_cart::IntegratorEntry& member = members[i];
    out += std::string(i ? ",\n  " : "\n  ") + "{\"name\": " + json_quoted(member.name) +
           ", \"order\": " + std::to_string(member.order) + ", \"symmetric\": " + (member.symmetric ? "true" : "false") +
           ", \"reversible\": " + (member.reversible() ? "true" : "false") +
           ", \"adaptive\": " + (member.adaptive() ? "true" : "false") +
           ", \"vector_stages\": " + (member.vector_stages ? "true" : "false") +
           ", \"kind\": " + json_quoted(birkhoff_cart::to_string(member.kind)) +
           ", \"takes_tolerance\": " + (member.takes_tolerance() ? "true" : "false") +
           ", \"description\": " + json_quoted(member.description) + "}";
  }
  return out + "],\n \"birkhoffian_forms\": " + json_list(birkhoff_cart::birkhoffian_form_names()) +
         ",\n \"step_controls\": " + json_list(birkhoff_cart::step_control_names()) + "}\n";
}

/// --list-integrators [--json] (alone on the command line): the registry as a table or as JSON.
/// Returns the exit status, or -1 when the command line does not ask for the listing.
int list_integrators_if_asked(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--list-integrators") != 0) return -1;
  if (argc == 2) {
    std::fputs(integrator_table().c_str(), stdout);
    return 0;
  }
  if (argc == 3 && std::strcmp(argv[2], "--json") == 0) {
    std::fputs(integrator_listing_json().c_str(), stdout);
    return 0;
  }
  std::fprintf(stderr, "cart_simulate: --list-integrators takes only --json, got '%s'\n", argv[2]);
  return kExitUsage;
}

std::string usage() {
  using birkhoff_cart::StepControl;
  const std::string fixed = birkhoff_cart::to_string(StepControl::kFixed);
  const std::string reversible = birkhoff_cart::to_string(StepControl::kReversible);
  const std::string adaptive = birkhoff_cart::to_string(StepControl::kAdaptive);
  return "usage: cart_simulate --scene FILE [--integrator NAME] [--step H] [--tolerance TOL]\n"
         "                     [--duration T] [--output-rate HZ] [--birkhoffian-form F] [--quiet]\n"
         "                     [--step-control " + alternatives(birkhoff_cart::step_control_names(), "|", "|") +
         "] [--position-tolerance M]\n"
         "                     [--global-error-estimate] [--on-accuracy-error fail|warn] [--random-scene SEED:K]\n"
         "                     [--event FIELD=VALUE[,rising|falling][,terminal]]... [--events-output FILE.csv]\n"
         "                     --output FILE.csv\n"
         "       cart_simulate --help | -h | --version\n"
         "       cart_simulate --list-integrators [--json]   (the table below; --json: for programs)\n"
         "  --scene FILE            scene YAML (config/scenes/*.yaml); it provides every default\n"
         "  --integrator NAME       a member of the registry (below)\n"
         "  --step H                step size [s], > 0; 1/HZ must be a whole multiple of it (fixed steps only)\n"
         "  --tolerance TOL         dopri5's absolute and relative local tolerance [-], >= 10 machine epsilon\n"
         "                          (2.2e-15); refused for the fixed-step members\n"
         "  --step-control C        " + fixed + " (steps of H), " + reversible +
         " (symmetric Birkhoffian members, free runs) or\n"
         "                          " + adaptive + " (Gauss members and dopri5, any scene): their own\n"
         "                          steps for --position-tolerance, rows at any --output-rate (docs/accuracy.md §4)\n"
         "  --position-tolerance M  " + reversible + " or " + adaptive +
         " step control: the position error [m] allowed at the horizon\n"
         "  --global-error-estimate  " + adaptive + " step control, Gauss members: estimate the position error\n"
         "                          of B the run gathers (a shadow run on doubled steps; the summary reports\n"
         "                          it); up to half the work again, the same steps (docs/accuracy.md §4.5)\n"
         "  --duration T            simulated time after the start [s], > 0\n"
         "  --output-rate HZ        output rows per simulated second [Hz], > 0\n"
         "  --birkhoffian-form F    " + alternatives(birkhoff_cart::birkhoffian_form_names(), ", ", " or ") + "\n"
         "  --quiet                 no progress lines on stderr\n"
         "  --random-scene SEED:K   scene K of the seeded random family (a random valid cart, start, step,\n"
         "                          duration and effects; docs/accuracy.md §3) instead of the file's, which\n"
         "                          gives the rest (integrator, accuracy guard); the other options still apply\n"
         "  --event E               record when a state field crosses a value, e.g. chi=0.3,rising,terminal\n"
         "                          (FIELD: t x y theta chi phi1..phi4 pi1 omega1 omega2, SI units; rising,\n"
         "                          falling or both; terminal stops the run there). Repeatable. Each crossing,\n"
         "                          located on the member's own step to 1e-12 s, is a line 'event ...' on\n"
         "                          stdout (docs/events.md)\n"
         "  --events-output FILE.csv  the crossings also as CSV: event,occurrence,t,x,y,theta,chi,phi1..phi4,\n"
         "                          pi1,omega1,omega2 (SI units, in time order)\n"
         "  --on-accuracy-error A   fail (default: exit 5 when the scene's accuracy guard reaches ERROR)\n"
         "                          or warn (exit 0; the summary still names the quantity)\n"
         "  --output FILE.csv       where to write t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,\n"
         "                          local_error_estimate\n" +
         integrator_table() +
         "Every option also takes the form --option=value.\n"
         "The rows are at t0 + k/HZ from the start to the end, both included; when the duration is not a\n"
         "whole number of output intervals, a last row is written at the end time t0 + T itself (reached\n"
         "by one shorter final step); at most 1e8 rows a run. Scene times are limited so that t + H stays\n"
         "exact to ~1e-6 H (docs/scenes.md). Runs longer than a second report progress on stderr (once a\n"
         "second at most).\n"
         "Exit status: 0 done; 2 bad arguments; 3 unusable scene, settings or output file;\n"
         "4 a step failed or the run stopped (the rows written so far are kept); 5 the accuracy guard\n"
         "reached ERROR (docs/accuracy.md; the summary on stdout names the quantity).\n";
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// The CSV could not be written (disk full, I/O error): the run stops at once.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double parse_positive(const std::string& option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value) || !(value > 0.0)) {
    throw UsageError("option " + option + " needs a finite number > 0, got '" + text + "'");
  }
  return value;
}

bool asks_for_help(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) return true;
  }
  return false;
}

std::map<std::string, std::string> parse_arguments(int argc, char** argv) {
  static const char* const kOptions[] = {"--scene",       "--integrator",       "--step",  "--tolerance",
                                         "--duration",    "--output-rate",      "--birkhoffian-form", "--output",
                                         "--on-accuracy-error", "--step-control", "--random-scene",
                                         "--position-tolerance", "--event", "--events-output"};
  std::map<std::string, std::string> values;
  for (int i = 1; i < argc; ++i) {
    std::string option = argv[i];
    std::optional<std::string> attached;  // the value of --option=value
    const std::size_t equals = option.find('=');
    if (option.rfind("--", 0) == 0 && equals != std::string::npos) {
      attached = option.substr(equals + 1);
      option.resize(equals);
    }
    if (option == "--quiet" || option == "--global-error-estimate") {  // flags without a value
      if (attached) throw UsageError("option " + option + " takes no value, got '" + option + "=" + *attached + "'");
      if (values.count(option)) throw UsageError("option " + option + " given twice");
      values[option] = "";
      continue;
    }
    bool known = false;
    for (const char* candidate : kOptions) known = known || option == candidate;
    if (!known) throw UsageError("unknown argument '" + std::string(argv[i]) + "'");
    if (!attached && i + 1 >= argc) throw UsageError("option " + option + " needs a value");
    const std::string value = attached ? *attached : argv[++i];
    if (option == "--event") {  // repeatable: the events, one per line
      if (value.find('\n') != std::string::npos) throw UsageError("option --event: a line break in '" + value + "'");
      values[option] += (values.count(option) && !values[option].empty() ? "\n" : "") + value;
      if (value.empty()) throw UsageError("option --event needs FIELD=VALUE[,rising|falling][,terminal], got ''");
      continue;
    }
    if (values.count(option)) throw UsageError("option " + option + " given twice");
    values[option] = value;
  }
  if (!values.count("--scene")) throw UsageError("missing --scene FILE");
  if (!values.count("--output")) throw UsageError("missing --output FILE.csv");
  return values;
}

/// `text` when it is one of `names`; else a UsageError naming the option, the choices and the
/// closest one to a typo.
std::string one_of(const std::string& option, const std::string& text, const std::vector<std::string>& names) {
  if (std::find(names.begin(), names.end(), text) != names.end()) return text;
  const std::string guess = birkhoff_cart::closest_name(text, names);
  throw UsageError("option " + option + " must be " + alternatives(names, ", ", " or ", "'") + ", got '" + text + "'" +
                   (guess.empty() ? "" : " (did you mean '" + guess + "'?)"));
}

/// Scene K of the random family SEED ("SEED:K", both whole numbers ≥ 0), on `base`.
Scene random_scene(const std::string& text, const Scene& base) {
  const auto colon = text.find(':');
  const auto whole = [&](const std::string& part) {
    if (part.empty() || part.size() > 19 || part.find_first_not_of("0123456789") != std::string::npos) {
      throw UsageError("option --random-scene needs SEED:K with whole numbers SEED, K >= 0, got '" + text + "'");
    }
    return static_cast<std::uint64_t>(std::stoull(part));
  };
  if (colon == std::string::npos) whole("");
  return birkhoff_cart::RandomSceneFamily(whole(text.substr(0, colon))).scene(base, whole(text.substr(colon + 1)));
}

/// Applies the command-line overrides to the scene's settings.
void apply_overrides(const std::map<std::string, std::string>& arguments, Scene& scene) {
  for (const auto& [option, text] : arguments) {
    if (option == "--integrator") scene.integrator.name = text;
    if (option == "--step") scene.integrator.step_size = parse_positive(option, text);
    if (option == "--tolerance") scene.integrator.tolerance = parse_positive(option, text);
    if (option == "--duration") scene.duration = parse_positive(option, text);
    if (option == "--output-rate") scene.output_rate = parse_positive(option, text);
    if (option == "--birkhoffian-form") {
      scene.integrator.birkhoffian_form =
          birkhoff_cart::parse_birkhoffian_form(one_of(option, text, birkhoff_cart::birkhoffian_form_names()));
    }
    if (option == "--step-control") {
      scene.integrator.step_control =
          birkhoff_cart::parse_step_control(one_of(option, text, birkhoff_cart::step_control_names()));
    }
    if (option == "--position-tolerance") scene.integrator.position_tolerance = parse_positive(option, text);
    if (option == "--global-error-estimate") scene.integrator.global_error_estimate = true;
    if (option == "--on-accuracy-error") one_of(option, text, {"fail", "warn"});
  }
  // Each tolerance means one thing and is refused where it would be ignored.
  const birkhoff_cart::IntegratorSettings& settings = scene.integrator;
  const bool controlled = settings.step_control != birkhoff_cart::StepControl::kFixed;
  const std::string control = birkhoff_cart::to_string(settings.step_control);
  const birkhoff_cart::IntegratorEntry* member = birkhoff_cart::find_integrator(settings.name);
  if (arguments.count("--tolerance") && !(member != nullptr && member->takes_tolerance())) {
    throw UsageError("option --tolerance is dopri5's local tolerance [-]; " + settings.name + " steps at " +
                     (controlled ? "the " + control + " step control's steps: give the position error [m] with "
                                                      "--position-tolerance M"
                                 : std::string("--step H (fixed steps; the Birkhoffian members choose their own "
                                               "steps for a position error with --step-control adaptive or "
                                               "reversible --position-tolerance M)")));
  }
  if (arguments.count("--position-tolerance") && !controlled) {
    throw UsageError("option --position-tolerance is the position error [m] for --step-control adaptive or "
                     "reversible; the run steps at fixed steps of --step H");
  }
  if (settings.global_error_estimate && settings.step_control != birkhoff_cart::StepControl::kAdaptive) {
    throw UsageError("option --global-error-estimate follows the grid of --step-control adaptive; the run steps "
                     "under '" + control + "'");
  }
  if (controlled && !(settings.position_tolerance > 0.0)) {
    throw UsageError("option --step-control " + control +
                     " needs --position-tolerance M (the position error [m] allowed at the horizon)");
  }
  if (controlled && arguments.count("--step")) {
    throw UsageError("option --step is the fixed-step members' step; under --step-control " + control +
                     " the member chooses its own steps and the rows come at --output-rate HZ");
  }
  // Under a step control the output step is the row interval: the rows need not fall on any step
  // of the member's (its dense output), so the scene's step_size does not constrain them. A row
  // interval beyond the run leaves the rows at its start and end, as at fixed steps.
  if (controlled) {
    if (1.0 / scene.output_rate > scene.duration) scene.output_rate = 1.0 / scene.duration;
    scene.integrator.step_size = 1.0 / scene.output_rate;
  }
}

/// At fixed steps the rows must fall on steps: a rate whose interval is no whole number of them is
/// refused naming --output-rate and --step.
void require_rows_on_steps(const birkhoff_cart::GuardedRun& guarded_run, const Scene& scene) {
  try {
    guarded_run.require_output_instants_on_steps();
  } catch (const std::invalid_argument& error) {
    std::ostringstream message;
    message.precision(17);
    message << "output_rate " << scene.output_rate << " Hz (--output-rate) puts rows between the fixed steps of "
            << "integrator.step_size " << scene.integrator.step_size << " s (--step): " << error.what()
            << "; choose a rate whose row interval is a whole number of steps, or a step control";
    throw std::invalid_argument(message.str());
  }
}

/// The most rows one run writes: 10^8 rows are about 30 GB of CSV.
constexpr double kMaxRows = 1e8;

/// Refuses a run whose rows (output_rate × duration + 1) exceed kMaxRows, naming the rate and the
/// duration: --output-rate 1e9 over 6 s started 6·10⁹ rows and filled the disk.
void require_row_count(const Scene& scene) {
  const double rows = std::floor(scene.output_rate * scene.duration) + 1.0;  // [-]
  if (rows <= kMaxRows) return;
  std::ostringstream message;
  message.precision(17);
  message << "output_rate " << scene.output_rate << " Hz (--output-rate) over duration " << scene.duration
          << " s (--duration) asks for " << rows << " rows, more than the limit of " << kMaxRows
          << " (about 300 bytes of CSV each): a lower --output-rate or a shorter --duration";
  throw std::invalid_argument(message.str());
}

/// The scene key a time limit blames, with the option that may have set it. Under a step control
/// the step h the limits read is the rows' interval 1/HZ (apply_overrides), so they name --output-rate.
std::string key_with_option(const std::string& key, const Scene& scene) {
  const bool controlled = scene.integrator.step_control != birkhoff_cart::StepControl::kFixed;
  if (controlled) {
    std::ostringstream rate;
    rate.precision(17);
    rate << "output rate " << scene.output_rate << " Hz (--output-rate): under a step control h is the rows' interval "
         << scene.integrator.step_size << " s";
    if (key == "integrator.step_size") return "output_rate (" + rate.str() + ")";
    if (key == "duration") return "duration (--duration) with the " + rate.str();
    return key + " with the " + rate.str();
  }
  if (key == "duration") return "duration (--duration)";
  if (key == "integrator.step_size") return "integrator.step_size (--step)";
  return key;
}

/// One CSV row at `time` [s], its numbers as %.17g writes them (csv_number.h).
void write_row(std::FILE* file, double time, const Simulation& simulation, birkhoff_cart::OdometrySensor* sensor) {
  const CartState& state = simulation.state();
  const birkhoff_cart::CartModel& model = simulation.model();
  std::string row;
  row.reserve(512);
  const auto add = [&row](double value) {
    birkhoff_cart::append_csv_number(row, value);
    row += ',';
  };
  for (double value : {time, state.x, state.y, state.heading, state.steering_angle, state.wheel_spin_angle[0],
                       state.wheel_spin_angle[1], state.wheel_spin_angle[2], state.wheel_spin_angle[3], state.arc_length,
                       state.forward_speed, state.steering_rate, model.energy(state), model.steering_momentum(state)}) {
    add(value);
  }
  const birkhoff_cart::StepStatistics& statistics = simulation.statistics();
  const double estimate = statistics.local_error_estimate_last_step;  // ê [-]; none before the first step
  if (birkhoff_cart::has_local_error_estimate(statistics) && std::isfinite(estimate)) {
    birkhoff_cart::append_csv_number(row, estimate);
  }
  if (sensor) {  // the odometry sensor's estimate of A and its standard deviations (docs/odometry_sensor.md)
    const birkhoff_cart::OdometryEstimate& odometry = sensor->read(state);
    for (double value : {odometry.x, odometry.y, odometry.heading,
                         std::sqrt(odometry.pose_covariance(0, 0) + odometry.pose_covariance(1, 1)),
                         std::sqrt(odometry.pose_covariance(2, 2))}) {
      row += ',';
      birkhoff_cart::append_csv_number(row, value);
    }
  }
  // The actuators' applied torques and the end-stop contact (docs/actuators.md), when enabled.
  const Simulation::ActuatorStatus actuators = simulation.actuator_status();
  if (actuators.steering_actuator) {
    row += ',';
    birkhoff_cart::append_csv_number(row, actuators.steering_applied);
  }
  if (actuators.drive_actuator) {
    row += ',';
    birkhoff_cart::append_csv_number(row, actuators.drive_applied);
  }
  if (actuators.end_stops) row += "," + std::to_string(actuators.end_stop_contact);
  row += '\n';
  std::fwrite(row.data(), 1, row.size(), file);
}

/// At most one line per kProgressPeriod of wall time: percent of scene time, real-time factor.
class ProgressReport {
 public:
  ProgressReport(bool enabled, double start_time, double end_time)
      : enabled_(enabled), start_time_(start_time), end_time_(end_time), wall_start_(Clock::now()),
        next_report_(wall_start_ + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(kProgressPeriod))) {}

  void update(double time) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (now < next_report_) return;
    next_report_ = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kProgressPeriod));
    const double wall = std::chrono::duration<double>(now - wall_start_).count();  // [s]
    const double done = time - start_time_;                                        // [s] of scene time
    std::fprintf(stderr, "cart_simulate: %5.1f %% of scene time (t = %.6g s of %.6g s), real-time factor %.3g\n",
                 100.0 * done / (end_time_ - start_time_), time, end_time_, done / wall);
  }

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  double start_time_, end_time_;  // [s]
  Clock::time_point wall_start_, next_report_;
};

/// The --event options' events (given one per line), a UsageError naming a malformed or repeated one.
std::vector<birkhoff_cart::StateEvent> parse_events(const std::string& lines) {
  std::vector<std::string> texts;
  std::string::size_type from = 0;
  for (;;) {
    const std::string::size_type end = lines.find('\n', from);
    texts.push_back(lines.substr(from, end == std::string::npos ? end : end - from));
    if (end == std::string::npos) break;
    from = end + 1;
  }
  try {
    return birkhoff_cart::state_field_events(texts);
  } catch (const std::invalid_argument& error) {
    throw UsageError(std::string("option --event: ") + error.what());
  }
}

/// Closes the CSV; false (with errno) when any write failed.
bool close_output(std::FILE* file) {
  const bool write_failed = std::ferror(file) != 0;
  const int saved_errno = errno;
  const bool close_failed = std::fclose(file) != 0;
  if (write_failed && !close_failed) errno = saved_errno != 0 ? saved_errno : EIO;
  return !write_failed && !close_failed;
}

/// The crossings as CSV rows in time order: event (its text, quoted), occurrence (1, 2, … per event),
/// t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2 (SI, %.17g); closes the file.
void write_event_rows(std::FILE* file, const std::vector<birkhoff_cart::StateEvent>& events) {
  std::fprintf(file, "event,occurrence,t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2\n");
  for (const birkhoff_cart::Occurrence& row : birkhoff_cart::occurrences_in_time_order(events)) {
    const CartState& s = events[row.event].states[row.index];
    std::fprintf(file, "\"%s\",%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                 events[row.event].name.c_str(), row.index + 1, row.time, s.x, s.y, s.heading, s.steering_angle,
                 s.wheel_spin_angle[0], s.wheel_spin_angle[1], s.wheel_spin_angle[2], s.wheel_spin_angle[3],
                 s.arc_length, s.forward_speed, s.steering_rate);
  }
  if (!close_output(file)) std::fprintf(stderr, "cart_simulate: writing the events' CSV failed: %s\n", std::strerror(errno));
}

int run(int argc, char** argv) {
  if (asks_for_help(argc, argv)) {
    std::fputs(usage().c_str(), stdout);
    return 0;
  }
  if (birkhoff_cart::print_version_if_asked(argc, argv, "cart_simulate")) return 0;
  const int listed = list_integrators_if_asked(argc, argv);
  if (listed >= 0) return listed;
  std::map<std::string, std::string> arguments;
  Scene scene;
  std::vector<birkhoff_cart::StateEvent> events;
  try {
    arguments = parse_arguments(argc, argv);
    scene = birkhoff_cart::load_scene(arguments.at("--scene"));
    if (arguments.count("--random-scene")) scene = random_scene(arguments.at("--random-scene"), scene);
    apply_overrides(arguments, scene);
    if (arguments.count("--event")) events = parse_events(arguments.at("--event"));
    if (arguments.count("--events-output") && events.empty()) {
      throw UsageError("option --events-output needs at least one --event");
    }
  } catch (const UsageError& error) {
    std::fprintf(stderr, "cart_simulate: %s\n%s", error.what(), usage().c_str());
    return kExitUsage;
  } catch (const std::exception& error) {  // SceneError, or e.g. std::bad_alloc while reading
    std::fprintf(stderr, "cart_simulate: %s\n", error.what());
    return kExitSettings;
  }

  // The run, its accuracy guard checked at the start, at every row's instant and at the end.
  std::unique_ptr<birkhoff_cart::GuardedRun> guarded_run;
  try {
    guarded_run = std::make_unique<birkhoff_cart::GuardedRun>(scene);
    const std::string drift = birkhoff_cart::paper_form_drift_warning(scene);  // the eᵗ form's h² drift
    if (!drift.empty()) std::fprintf(stderr, "cart_simulate: %s\n", drift.c_str());
    require_rows_on_steps(*guarded_run, scene);
    require_row_count(scene);
  } catch (const birkhoff_cart::TimeLimitError& error) {
    std::fprintf(stderr, "cart_simulate: scene %s with the given options: key '%s': %s\n", scene.source_path.c_str(),
                 key_with_option(error.key(), scene).c_str(), error.problem().c_str());
    return kExitSettings;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "cart_simulate: %s\n", error.what());
    return kExitSettings;
  }

  const std::string output_path = arguments.at("--output");
  std::FILE* file = std::fopen(output_path.c_str(), "w");
  if (!file) {
    std::fprintf(stderr, "cart_simulate: cannot write '%s': %s\n", output_path.c_str(), std::strerror(errno));
    return kExitSettings;
  }
  std::FILE* events_file = nullptr;  // --events-output: the crossings as CSV, written at the end
  if (arguments.count("--events-output")) {
    events_file = std::fopen(arguments.at("--events-output").c_str(), "w");
    if (!events_file) {
      std::fprintf(stderr, "cart_simulate: cannot write '%s': %s\n", arguments.at("--events-output").c_str(),
                   std::strerror(errno));
      std::fclose(file);
      return kExitSettings;
    }
  }
  const Simulation& simulation = guarded_run->simulation();
  std::optional<birkhoff_cart::OdometrySensor> sensor;
  if (scene.odometry_sensor) {
    sensor.emplace(*scene.odometry_sensor, simulation.model());
    sensor->start(simulation.state(), true);
  }
  std::fprintf(file, "t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate%s%s%s%s\n",
               sensor ? ",odom_x,odom_y,odom_theta,odom_sigma_position,odom_sigma_theta" : "",
               scene.actuators.steering ? ",steering_torque_applied" : "",
               scene.actuators.drive ? ",drive_torque_applied" : "", scene.actuators.end_stops ? ",end_stop_contact" : "");
  const birkhoff_cart::StepSchedule& schedule = simulation.schedule();
  const double start_time = schedule.start_time;  // t0 [s]
  const birkhoff_cart::AccuracyGuard& guard = guarded_run->guard();
  ProgressReport progress(!arguments.count("--quiet"), start_time, schedule.end_time);
  std::uint64_t rows = 0;
  const auto write_state = [&](double time) {
    write_row(file, time, simulation, sensor ? &*sensor : nullptr);
    if (std::ferror(file)) throw OutputError(std::string("writing the CSV failed: ") + std::strerror(errno));
    ++rows;
  };
  // The events: crossings located on each own step of a member with its own steps (the grid
  // observer), else on each step of the schedule; printed when the run ends or stops.
  std::optional<birkhoff_cart::EventLocator> locator;
  if (!events.empty()) {
    try {
      locator.emplace(simulation, events);
    } catch (const std::invalid_argument& error) {
      std::fclose(file);
      std::fprintf(stderr, "cart_simulate: %s\n", error.what());
      return kExitSettings;
    }
    if (simulation.takes_own_steps()) {
      guarded_run->simulation().observe_grid([&](const CartState& stepped_to) { locator->step_to(stepped_to); });
    }
  }
  const auto print_events = [&] {
    for (const birkhoff_cart::Occurrence& occurrence : birkhoff_cart::occurrences_in_time_order(events)) {
      std::printf("event %s\n", birkhoff_cart::describe_occurrence(events[occurrence.event], occurrence.index).c_str());
    }
    if (events_file) write_event_rows(events_file, events);
    if (locator && locator->stopped()) {
      std::printf("cart_simulate: stopped by the terminal event %s at t = %.17g s (the run stopped at the first "
                  "step that reached it, t = %.17g s; no row after the event)\n",
                  events[locator->stopping_event()].name.c_str(), locator->stop_state().time, simulation.state().time);
    }
  };
  try {
    write_state(start_time);
    // A row at each output instant the run reaches (t0 + k/HZ on the whole steps, and the end t0 + T).
    while (!simulation.at_end()) {
      const std::optional<double> instant = guarded_run->step();
      if (locator && !simulation.takes_own_steps()) locator->step_to(simulation.state());
      // A member with its own steps may find a terminal crossing ahead of the schedule (its own
      // step reaches beyond the step asked for): the rows up to the crossing are still written.
      const bool stopped = locator && locator->stopped();
      if (instant && !(stopped && *instant > locator->stop_state().time)) write_state(*instant);
      progress.update(simulation.state().time);
      if (stopped && simulation.state().time >= locator->stop_state().time) break;
    }
  } catch (const OutputError& error) {
    close_output(file);
    std::fprintf(stderr, "cart_simulate: %s at t = %.17g s (%llu rows complete in %s)\n", error.what(),
                 simulation.state().time, static_cast<unsigned long long>(rows), output_path.c_str());
    return kExitSettings;
  } catch (const std::exception& error) {  // StepError, or anything unexpected: keep the rows
    const bool kept = close_output(file);
    std::fprintf(stderr, "cart_simulate: %s after t = %.17g s (%llu rows %s %s): %s\n",
                 dynamic_cast<const birkhoff_cart::StepError*>(&error) ? "step failed" : "run stopped",
                 simulation.state().time, static_cast<unsigned long long>(rows),
                 kept ? "written to" : "NOT all written to", output_path.c_str(), error.what());
    print_events();
    std::printf("cart_simulate %s", birkhoff_cart::run_summary(simulation, guard).c_str());
    return kExitStepFailed;
  }
  if (!close_output(file)) {
    std::fprintf(stderr, "cart_simulate: error writing '%s': %s\n", output_path.c_str(), std::strerror(errno));
    return kExitSettings;
  }
  print_events();
  std::printf("cart_simulate %s", birkhoff_cart::run_summary(simulation, guard).c_str());
  if (sensor) std::printf("%s\n", birkhoff_cart::odometry_drift_line(*sensor, simulation.state(), simulation.model()).c_str());
  if (guard.level() == birkhoff_cart::AccuracyLevel::kError) {
    const bool warn_only = arguments.count("--on-accuracy-error") && arguments.at("--on-accuracy-error") == "warn";
    std::fprintf(stderr, "cart_simulate: accuracy %s%s%s\n", guard.summary().c_str(),
                 birkhoff_cart::accuracy_binding_note(simulation, guard).c_str(),
                 warn_only ? " (--on-accuracy-error warn: exit 0)" : "");
    if (!warn_only) return kExitAccuracy;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // No exception leaves main: run() maps every expected one to its exit status; this is the last net.
  try {
    return run(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "cart_simulate: unexpected error: %s\n", error.what());
  } catch (...) {
    std::fprintf(stderr, "cart_simulate: unexpected error of unknown type\n");
  }
  return kExitStepFailed;
}

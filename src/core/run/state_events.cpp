// Events of a cart run (state_events.h, docs/events.md): the field events' text and the locator.
#include "birkhoff_cart/core/run/state_events.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "birkhoff_cart/core/integrators/crossing.h"
#include "birkhoff_cart/core/run/simulation.h"

namespace birkhoff_cart {

const std::vector<std::string>& event_field_names() {
  static const std::vector<std::string> names = {"t",    "x",    "y",    "theta", "chi",    "phi1",  "phi2",
                                                 "phi3", "phi4", "pi1",  "omega1", "omega2"};
  return names;
}

double state_field(const CartState& state, const std::string& field) {
  if (field == "t") return state.time;              // [s]
  if (field == "x") return state.x;                 // [m]
  if (field == "y") return state.y;                 // [m]
  if (field == "theta") return state.heading;       // [rad]
  if (field == "chi") return state.steering_angle;  // [rad]
  if (field.size() == 4 && field.compare(0, 3, "phi") == 0 && field[3] >= '1' && field[3] <= '4') {
    return state.wheel_spin_angle[static_cast<std::size_t>(field[3] - '1')];  // [rad]
  }
  if (field == "pi1") return state.arc_length;        // [m]
  if (field == "omega1") return state.forward_speed;  // [m/s]
  if (field == "omega2") return state.steering_rate;  // [rad/s]
  std::string known;
  for (const std::string& name : event_field_names()) known += (known.empty() ? "" : ", ") + name;
  throw std::invalid_argument("unknown state field '" + field + "' (one of " + known + ")");
}

namespace {

/// `text` as a message shows it: control bytes as \xNN, at most 60 bytes (then "…").
std::string shown(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < 60; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      static const char* const kHex = "0123456789abcdef";
      out += std::string("\\x") + kHex[c >> 4] + kHex[c & 15];
    } else {
      out += text[i];
    }
  }
  if (text.size() > 60) out += "…";
  return out;
}

}  // namespace

StateEvent state_field_event(const std::string& text) {
  const auto refuse = [&](const std::string& problem) {
    return std::invalid_argument("event '" + shown(text) + "': " + problem +
                                 " (FIELD=VALUE[,rising|falling][,terminal], e.g. chi=0.3,rising,terminal)");
  };
  std::vector<std::string> parts;
  std::string::size_type from = 0;
  for (;;) {
    const std::string::size_type comma = text.find(',', from);
    parts.push_back(text.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  const std::string::size_type equals = parts[0].find('=');
  if (equals == std::string::npos) throw refuse("no '=' between the field and its value");
  const std::string field = parts[0].substr(0, equals);
  const std::string value_text = parts[0].substr(equals + 1);
  if (std::find(event_field_names().begin(), event_field_names().end(), field) == event_field_names().end()) {
    std::string known;
    for (const std::string& name : event_field_names()) known += (known.empty() ? "" : ", ") + name;
    throw refuse("unknown state field '" + shown(field) + "' (one of " + known + ")");
  }
  char* end = nullptr;
  errno = 0;
  const double value = value_text.empty() ? 0.0 : std::strtod(value_text.c_str(), &end);
  const bool overflow = errno == ERANGE && std::abs(value) > 1.0;  // an underflow to a subnormal is a number
  if (value_text.empty() || end != value_text.c_str() + value_text.size() || overflow || !std::isfinite(value)) {
    throw refuse("the value '" + shown(value_text) + "' is no finite number");
  }
  StateEvent event;
  event.name = text;
  event.g = [field, value](const CartState& state) { return state_field(state, field) - value; };
  bool direction_given = false;
  for (std::size_t k = 1; k < parts.size(); ++k) {
    const std::string& flag = parts[k];
    if (flag == "rising" || flag == "falling") {
      if (direction_given) throw refuse("a second direction '" + flag + "'");
      direction_given = true;
      event.direction = flag == "rising" ? 1.0 : -1.0;
    } else if (flag == "terminal") {
      if (event.terminal_after != 0) throw refuse("'terminal' twice");
      event.terminal_after = 1;
    } else {
      throw refuse("unknown flag '" + shown(flag) + "' (rising, falling or terminal)");
    }
  }
  return event;
}

std::vector<StateEvent> state_field_events(const std::vector<std::string>& texts) {
  std::vector<StateEvent> events;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (texts[j] == texts[i]) {
        throw std::invalid_argument("event '" + shown(texts[i]) + "' given twice (each crossing would be reported twice)");
      }
    }
    events.push_back(state_field_event(texts[i]));
  }
  return events;
}

EventLocator::EventLocator(const Simulation& simulation, std::vector<StateEvent>& events, double time_tolerance,
                           StepStatistics* work)
    : simulation_(simulation),
      events_(events),
      time_tolerance_(time_tolerance),
      own_steps_(simulation.takes_own_steps()),
      before_(simulation.state()),
      work_(work ? work : &own_work_) {
  if (!(time_tolerance > 0.0)) throw std::invalid_argument("the events' time tolerance must be > 0 [s]");
  if (!own_steps_ && !events.empty() && !simulation.at_end()) {
    try {  // refused here, by the core's reason, rather than at the first crossing
      const double next = std::min(before_.time + 0.5 * simulation.step_size(), simulation.end_time());
      simulation.state_by_one_step(before_, next);
    } catch (const std::logic_error& error) {
      throw std::invalid_argument(std::string("events at fixed steps: ") + error.what() +
                                  "; dopri5 (integrator dopri5: its own steps, with a dense output) locates "
                                  "them on any scene");
    }
  }
  for (const StateEvent& event : events_) g_before_.push_back(value(event, before_));
}

double EventLocator::value(const StateEvent& event, const CartState& state) const {
  const double g = event.g(state);
  if (std::isnan(g)) {
    std::ostringstream text;
    text.precision(17);
    text << "event '" << event.name << "' is NaN at t = " << state.time << " s";
    throw std::invalid_argument(text.str());
  }
  return g;
}

bool EventLocator::state_in_step(double time, CartState& out) {
  if (own_steps_) return simulation_.newest_step_state(time, out, work_);
  out = simulation_.state_by_one_step(before_, time, work_);
  return true;
}

bool EventLocator::step_to(const CartState& stepped_to) {
  // An own step past the run's end (dopri5's and the reversible control's last, which the run
  // leaves by a side step to the end) is read up to the end only.
  CartState clipped;
  const bool beyond_end = own_steps_ && stepped_to.time > simulation_.end_time();
  if (beyond_end && !simulation_.newest_step_state(simulation_.end_time(), clipped, work_)) return stopped_;
  const CartState& after = beyond_end ? clipped : stepped_to;
  if (!(after.time > before_.time)) return stopped_;  // no time passed: no step to look in
  std::vector<Found> found;
  g_after_.resize(events_.size());  // reused: no allocation per step
  for (std::size_t i = 0; i < events_.size(); ++i) {
    const StateEvent& event = events_[i];
    g_after_[i] = value(event, after);
    const double g0 = g_before_[i];
    const double g1 = g_after_[i];
    // g reaches zero or passes it. A step that starts at zero is none: that zero was the run's start,
    // or the end of the step that reached it (counted there once), and a g that stays at zero never
    // crosses (integrate()'s rule, system_integration.h).
    const bool up = g0 < 0.0 && g1 >= 0.0;
    const bool down = g0 > 0.0 && g1 <= 0.0;
    if (!(event.direction > 0.0 ? up : event.direction < 0.0 ? down : up || down)) continue;
    CartState at = after;
    double time = after.time;  // [s]
    if (state_in_step(0.5 * (before_.time + after.time), at)) {
      const auto g_at = [&](double t) {
        CartState probe;
        state_in_step(t, probe);
        return value(event, probe);
      };
      time = locate_crossing(g_at, before_.time, g0, after.time, g1, time_tolerance_).time;
      if (time == after.time) {
        at = after;
      } else if (time == before_.time) {
        at = before_;
      } else {
        state_in_step(time, at);
      }
    } else {
      // No dense output on this step (a grid restarted at an actuator's kink): the step's end,
      // where g has reached zero or passed it, so that no crossing is reported early.
      at = after;
    }
    found.push_back({time, i, at});
  }
  std::swap(g_before_, g_after_);
  before_ = after;
  std::stable_sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return a.time < b.time; });
  record(found);
  return stopped_;
}

void EventLocator::record(const std::vector<Found>& found) {
  for (const Found& crossing : found) {
    if (stopped_) {  // after a terminal crossing: held until resume()
      pending_.push_back(crossing);
      continue;
    }
    StateEvent& event = events_[crossing.event];
    event.times.push_back(crossing.time);
    event.states.push_back(crossing.state);
    if (event.terminal_after > 0 && event.times.size() >= event.terminal_after) {
      stopped_ = true;
      stop_state_ = crossing.state;
      stopping_event_ = crossing.event;
    }
  }
}

bool EventLocator::resume() {
  stopped_ = false;
  std::vector<Found> held;
  held.swap(pending_);
  record(held);
  return stopped_;
}

std::vector<Occurrence> occurrences_in_time_order(const std::vector<StateEvent>& events) {
  std::vector<Occurrence> occurrences;
  for (std::size_t i = 0; i < events.size(); ++i) {
    for (std::size_t k = 0; k < events[i].times.size(); ++k) occurrences.push_back({events[i].times[k], i, k});
  }
  std::stable_sort(occurrences.begin(), occurrences.end(),
                   [](const Occurrence& a, const Occurrence& b) { return a.time < b.time; });
  return occurrences;
}

std::string describe_occurrence(const StateEvent& event, std::size_t occurrence) {
  const CartState& s = event.states.at(occurrence);
  std::ostringstream text;
  text.precision(17);
  text << event.name << " at t = " << event.times.at(occurrence) << " s: x = " << s.x << " m, y = " << s.y
       << " m, theta = " << s.heading << " rad, chi = " << s.steering_angle << " rad, omega1 = " << s.forward_speed
       << " m/s, omega2 = " << s.steering_rate << " rad/s";
  return text.str();
}

}  // namespace birkhoff_cart

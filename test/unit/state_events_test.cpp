// Events of a cart run (state_events.h): the text of a field event, and crossings located by the
// EventLocator on the paper's special case, whose closed form (eq. (3.9)) gives chi = t and
// pi1 = 1 + ln tan(t/2): chi crosses 2.5 rad at t = 2.5 s, pi1 crosses 1.2 m at t = 2 atan(e^0.2).
// At fixed steps, under the adaptive control and with dopri5, each within 1e-10 s.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "birkhoff_cart/core/run/simulation.h"
#include "birkhoff_cart/core/run/state_events.h"
#include "birkhoff_cart/core/scene/scene.h"

namespace birkhoff_cart {
namespace {

const double kPi1CrossingTime = 2.0 * std::atan(std::exp(0.2));  // [s]: 1 + ln tan(t/2) = 1.2

Scene paper_special(const std::string& member, const std::string& control, double step_size = 0.01) {
  Scene scene = load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/paper_special.yaml");
  scene.integrator.name = member;
  scene.integrator.step_size = step_size;  // [s]
  if (control == "adaptive") {
    scene.integrator.step_control = StepControl::kAdaptive;
    scene.integrator.position_tolerance = 1e-12;
  }
  if (member == "dopri5") scene.integrator.tolerance = 1e-13;
  return scene;
}

/// Runs `simulation` to its end (or a terminal event) with the locator watching, as cart_simulate does.
void run_with_events(Simulation& simulation, EventLocator& locator) {
  if (simulation.takes_own_steps()) {
    simulation.observe_grid([&](const CartState& stepped_to) { locator.step_to(stepped_to); });
  }
  while (!simulation.at_end() && !locator.stopped()) {
    simulation.step_on_schedule();
    if (!simulation.takes_own_steps()) locator.step_to(simulation.state());
  }
  simulation.observe_grid({});
}

TEST(StateFieldEvent, ReadsFieldValueDirectionAndTerminal) {
  const StateEvent chi = state_field_event("chi=0.3,rising,terminal");
  EXPECT_EQ(chi.name, "chi=0.3,rising,terminal");
  EXPECT_EQ(chi.direction, 1.0);
  EXPECT_EQ(chi.terminal_after, 1u);
  CartState state;
  state.steering_angle = 0.5;
  EXPECT_DOUBLE_EQ(chi.g(state), 0.2);
  const StateEvent y = state_field_event("y=-2.5e-1,falling");
  EXPECT_EQ(y.direction, -1.0);
  EXPECT_EQ(y.terminal_after, 0u);
  state.y = 1.0;
  EXPECT_DOUBLE_EQ(y.g(state), 1.25);
  EXPECT_EQ(state_field_event("omega1=0").direction, 0.0);
  state.wheel_spin_angle[2] = 7.0;
  EXPECT_DOUBLE_EQ(state_field_event("phi3=1").g(state), 6.0);
}

TEST(StateFieldEvent, RefusesMalformedTextsByName) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"chi", "no '='"},          {"speed=1", "unknown state field 'speed'"},
      {"chi=abc", "'abc' is no finite number"}, {"chi=nan", "no finite number"},
      {"chi=", "no finite number"}, {"chi=1,up", "unknown flag 'up'"},
      {"chi=1,rising,falling", "a second direction"}, {"chi=1,terminal,terminal", "'terminal' twice"},
      {"phi5=1", "unknown state field 'phi5'"}, {"chi=1e999", "no finite number"}};
  for (const auto& [text, problem] : cases) {
    try {
      state_field_event(text);
      ADD_FAILURE() << text << " was taken";
    } catch (const std::invalid_argument& error) {
      const std::string what = error.what();
      EXPECT_NE(what.find("event '" + text + "'"), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
    }
  }
}

struct MemberUnderControl {
  std::string member;
  std::string control;
  double step_size;  ///< [s]: a crossing carries its run's own error (birkhoff4 at 10 ms: 3e-9 s)
};

class CrossingsOnThePapersCase : public ::testing::TestWithParam<MemberUnderControl> {};

TEST_P(CrossingsOnThePapersCase, AreFoundAtTheClosedFormsTimes) {
  Simulation simulation(paper_special(GetParam().member, GetParam().control, GetParam().step_size));
  std::vector<StateEvent> events = {state_field_event("chi=2.5"), state_field_event("pi1=1.2,rising"),
                                    state_field_event("chi=2.5,falling"), state_field_event("chi=1")};
  EventLocator locator(simulation, events);
  run_with_events(simulation, locator);
  ASSERT_TRUE(simulation.at_end());
  EXPECT_FALSE(locator.stopped());
  ASSERT_EQ(events[0].times.size(), 1u);
  EXPECT_NEAR(events[0].times[0], 2.5, 1e-10);
  EXPECT_NEAR(events[0].states[0].steering_angle, 2.5, 1e-10);
  EXPECT_EQ(events[0].states[0].time, events[0].times[0]);
  ASSERT_EQ(events[1].times.size(), 1u);
  EXPECT_NEAR(events[1].times[0], kPi1CrossingTime, 1e-10);
  EXPECT_NEAR(events[1].states[0].arc_length, 1.2, 1e-10);
  EXPECT_TRUE(events[2].times.empty()) << "chi rises through 2.5: no falling crossing";
  EXPECT_TRUE(events[3].times.empty()) << "chi starts at pi/2 > 1 and only rises";
  // At fixed steps the states inside a step are reached by steps beside the run: their work is the locator's.
  if (!simulation.takes_own_steps()) {
    EXPECT_GT(locator.work().rhs_evaluations, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Members, CrossingsOnThePapersCase,
                         ::testing::Values(MemberUnderControl{"birkhoff_gauss8", "fixed", 0.01},
                                           MemberUnderControl{"birkhoff4", "fixed", 0.001},
                                           MemberUnderControl{"birkhoff_gauss8", "adaptive", 0.01},
                                           MemberUnderControl{"dopri5", "fixed", 0.01}),
                         [](const ::testing::TestParamInfo<MemberUnderControl>& info) {
                           return info.param.member + "_" + info.param.control;
                         });

TEST(EventLocator, ATerminalEventStopsAtItsCrossingAndRecordsNothingAfter) {
  for (const std::string& control : std::vector<std::string>{"fixed", "adaptive"}) {
    Simulation simulation(paper_special("birkhoff_gauss8", control));
    std::vector<StateEvent> events = {state_field_event("chi=2.5"), state_field_event("pi1=1.2,terminal")};
    EventLocator locator(simulation, events);
    run_with_events(simulation, locator);
    ASSERT_TRUE(locator.stopped()) << control;
    EXPECT_EQ(locator.stopping_event(), 1u);
    EXPECT_NEAR(locator.stop_state().time, kPi1CrossingTime, 1e-10) << control;
    EXPECT_FALSE(simulation.at_end());
    EXPECT_LT(simulation.state().time, 2.5) << control << ": the run went on past the stop";
    EXPECT_TRUE(events[0].times.empty()) << control;
    EXPECT_TRUE(locator.step_to(simulation.state()));  // stopped: nothing more
    EXPECT_TRUE(events[0].times.empty());
  }
}

TEST(EventLocator, ResumeRecordsTheCrossingsHeldAfterATerminalOne) {
  // chi = t crosses 2.002 and 2.003 inside one step of 10 ms (from pi/2 + 0.43 = 2.0008 s): the
  // terminal one stops the run, the other is held until the run goes on (the node's ~pause false).
  for (const std::string& control : std::vector<std::string>{"fixed", "adaptive"}) {
    Simulation simulation(paper_special("birkhoff_gauss8", control));
    std::vector<StateEvent> events = {state_field_event("chi=2.002,terminal"), state_field_event("chi=2.003")};
    EventLocator locator(simulation, events);
    run_with_events(simulation, locator);
    ASSERT_TRUE(locator.stopped()) << control;
    EXPECT_NEAR(locator.stop_state().time, 2.002, 1e-10) << control;
    EXPECT_TRUE(events[1].times.empty()) << control << ": recorded past the terminal crossing";
    EXPECT_FALSE(locator.resume()) << control;
    run_with_events(simulation, locator);
    EXPECT_TRUE(simulation.at_end()) << control;
    ASSERT_EQ(events[1].times.size(), 1u) << control;
    EXPECT_NEAR(events[1].times[0], 2.003, 1e-10) << control;
    EXPECT_EQ(events[0].times.size(), 1u) << control;
  }
}

TEST(EventLocator, AZeroReachedAtAStepsEndIsOneCrossingAndAZeroHeldIsNone) {
  // The state's time lands on t0 + n h exactly: t = that time is reached at a step's end.
  Simulation probe(paper_special("birkhoff_gauss8", "fixed"));
  for (int n = 0; n < 20; ++n) probe.step();
  char text[64];
  std::snprintf(text, sizeof text, "t=%.17g", probe.state().time);
  Simulation simulation(paper_special("birkhoff_gauss8", "fixed"));
  std::vector<StateEvent> events = {state_field_event(text), state_field_event(std::string(text) + ",rising")};
  StateEvent held;  // zero all along
  held.name = "held";
  held.g = [](const CartState&) { return 0.0; };
  events.push_back(held);
  EventLocator locator(simulation, events);
  run_with_events(simulation, locator);
  ASSERT_EQ(events[0].times.size(), 1u) << text;
  EXPECT_EQ(events[0].times[0], probe.state().time);
  EXPECT_EQ(events[1].times.size(), 1u);
  EXPECT_TRUE(events[2].times.empty()) << events[2].times.size() << " crossings of a g that stays at zero";
}

TEST(StateFieldEvents, RefuseATextGivenTwiceAndShowLongOrControlTextsBounded) {
  EXPECT_EQ(state_field_events({"chi=0.1", "chi=0.1,rising"}).size(), 2u);
  try {
    state_field_events({"chi=0.1", "x=2", "chi=0.1"});
    ADD_FAILURE() << "a repeated event was taken";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("event 'chi=0.1' given twice"), std::string::npos) << error.what();
  }
  EXPECT_EQ(state_field_event("chi=1e-320").g(CartState{}), -1e-320);  // a subnormal is a number
  try {
    state_field_event(std::string(5000, 'q') + "\x01=1");
    ADD_FAILURE();
  } catch (const std::invalid_argument& error) {
    EXPECT_LT(std::string(error.what()).size(), 400u) << error.what();
  }
  try {
    state_field_event("ch\ti=1");
    ADD_FAILURE();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'ch\\x09i=1'"), std::string::npos) << error.what();
  }
}

TEST(EventLocator, AZeroAtTheStartIsNoCrossing) {
  Simulation simulation(paper_special("birkhoff_gauss8", "fixed"));
  std::vector<StateEvent> events = {state_field_event("chi=1.5707963267948966")};
  EventLocator locator(simulation, events);
  run_with_events(simulation, locator);
  EXPECT_TRUE(events[0].times.empty());
}

TEST(EventLocator, RefusesWhatItCannotLocate) {
  Simulation paper(paper_special("birkhoff_gauss8", "fixed"));
  std::vector<StateEvent> events = {state_field_event("chi=2")};
  EXPECT_THROW(EventLocator(paper, events, 0.0), std::invalid_argument);
  // Fixed steps with actuators: the states between steps move with the run (state_by_one_step's reason).
  Simulation actuated(load_scene(std::string(BIRKHOFF_CART_SOURCE_DIR) + "/config/scenes/steering_actuator.yaml"));
  ASSERT_FALSE(actuated.takes_own_steps());
  try {
    EventLocator locator(actuated, events);
    ADD_FAILURE() << "events at fixed steps with actuators were taken";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("events at fixed steps"), std::string::npos) << error.what();
  }
  // A g that is NaN is refused by name.
  std::vector<StateEvent> broken(1);
  broken[0].name = "broken";
  broken[0].g = [](const CartState&) { return std::nan(""); };
  try {
    EventLocator locator(paper, broken);
    ADD_FAILURE() << "a NaN event was taken";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("event 'broken' is NaN"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace birkhoff_cart

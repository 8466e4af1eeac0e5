"""simulator.solve() (docs/python.md "solve: a whole run shaped like solve_ivp's"): the result object
(t, y, the member's own steps, sol, counts, status) against the Simulation's own runs, and events
located on the dense output against the paper's special case in closed form (eq. (3.9): chi = t,
pi1 = 1 + ln tan(t/2)) and against a much finer run.

Run by scripts/run_tests.sh (catkin's run_tests: pytest-test_simulator_solve.xml), or after
`source .ws/devel/setup.bash`: python3 -m pytest test/python/test_simulator_solve.py.
"""
import math
import pathlib

import numpy as np
import pytest

from birkhoff_cart import simulator

SCENES = pathlib.Path(__file__).resolve().parents[2] / "config" / "scenes"
FIELD = {name: index for index, name in enumerate(simulator.STATE_FIELDS)}
N_FIELDS = len(simulator.STATE_FIELDS)

# The paper's special case from t0 = pi/2 to 3 s: chi = t and pi1 = 1 + ln tan(t/2) exactly.
GAUSS8_ADAPTIVE = {"name": "birkhoff_gauss8", "step_control": "adaptive", "position_tolerance": 1e-12,
                   "step_size": 0.05}
DOPRI5 = {"name": "dopri5", "step_size": 0.01, "tolerance": 1e-13}


def scene(name, integrator=None, **overrides):
    document = {"reference": None}
    document.update(overrides)
    if integrator:
        document["integrator"] = integrator
    return simulator.load_scene(str(SCENES / f"{name}.yaml"), document)


def event(function, terminal=False, direction=0.0):
    function.terminal = terminal
    function.direction = direction
    return function


# --- the result object ----------------------------------------------------------------------------

@pytest.mark.parametrize("integrator", [GAUSS8_ADAPTIVE, DOPRI5])
def test_the_result_holds_the_own_steps_and_equals_the_simulation_at_them(integrator):
    paper = scene("paper_special", integrator)
    result = simulator.solve(paper)
    assert result.status == 0 and result.success and "end" in result.message
    assert result.y.shape == (N_FIELDS, result.t.size) and result.t.size == result.nsteps + 1
    assert np.array_equal(result.t, result.y[FIELD["t"]])
    assert np.array_equal(result.t, result.t_steps) and np.array_equal(result.y, result.y_steps)
    assert result.t[0] == paper.start_time and result.t[-1] == pytest.approx(3.0, abs=1e-15)
    assert np.all(np.diff(result.t) > 0)
    # Own steps, not the scene's h: a step control chooses them.
    assert result.nsteps == result.statistics["internal_steps"]
    assert not np.allclose(np.diff(result.t), paper.step_size)
    # The same run as the Simulation's asked for the states at t0 + h and the end, as solve() asks:
    # its end state bit for bit, and its counts.
    sim = simulator.Simulation(paper)
    assert np.array_equal(sim.run_to([paper.start_time + paper.step_size, sim.end_time])[1], result.y[:, -1])
    assert result.nfev == sim.statistics()["rhs_evaluations"] > 0
    # And the run of every step h: the Gauss member's own steps do not depend on the instants it is
    # asked for, bit for bit; dopri5's, in the last digits (its output at every h).
    stepped = simulator.Simulation(paper).run()
    if integrator is GAUSS8_ADAPTIVE:
        assert np.array_equal(stepped, result.y[:, -1])
    print(f"{integrator['name']}: end state against the run of every step h: "
          f"{np.abs(stepped - result.y[:, -1]).max():.1e}")
    assert np.abs(stepped - result.y[:, -1]).max() < 1e-11
    assert result.sol is None and result.t_events is None
    # Against the closed form at every own step.
    chi_error = np.abs(result.y[FIELD["chi"]] - result.t).max()
    arc_error = np.abs(result.y[FIELD["pi1"]] - (1 + np.log(np.tan(result.t / 2)))).max()
    print(f"{integrator['name']}: {result.nsteps} own steps, chi error {chi_error:.2e} rad, "
          f"pi1 error {arc_error:.2e} m")
    assert chi_error < 1e-9 and arc_error < 1e-9


def test_t_eval_between_long_steps_takes_the_side_steps_run_to_takes():
    # gauss8 at 1e-6 m takes steps of ~0.1-0.6 s on free_coast: many t_eval instants at 100 Hz lie where
    # the dense output's own estimate exceeds the tolerance. solve() then takes the side step run_to()
    # takes there (bit for bit), and every state is within the tolerance of a tight dopri5 run, where
    # reading the interpolant there ended up to 5.0e-4 m off.
    integrator = {"name": "birkhoff_gauss8", "step_control": "adaptive", "position_tolerance": 1e-6,
                  "step_size": 0.01}
    free = scene("free_coast", integrator)
    t_eval = np.arange(0.0, 6.0, 0.01)
    result = simulator.solve(free, t_eval=t_eval)
    run_to = simulator.Simulation(free).run_to(t_eval)
    assert np.array_equal(result.y.T, run_to)
    tight = simulator.Simulation(scene("free_coast", {"name": "dopri5", "step_size": 0.01, "tolerance": 1e-13}))
    reference = tight.run_to(t_eval)
    error = np.hypot(*(result.y[[FIELD["x"], FIELD["y"]]] - reference.T[[FIELD["x"], FIELD["y"]]]))
    speed_error = np.abs(result.y[FIELD["omega1"]] - reference.T[FIELD["omega1"]])
    print(f"free_coast gauss8 1e-6 m, t_eval at 100 Hz: worst {error.max():.2e} m, omega1 {speed_error.max():.2e} m/s")
    assert error.max() < 2e-6 and speed_error.max() < 1e-5


@pytest.mark.parametrize("integrator", [GAUSS8_ADAPTIVE, DOPRI5])
def test_t_eval_gives_run_to_states_and_sol_gives_the_same_run_at_any_instant(integrator):
    paper = scene("paper_special", integrator)
    t_eval = np.linspace(paper.start_time, 3.0, 37)
    result = simulator.solve(paper, t_eval=t_eval, dense_output=True)
    assert result.y.shape == (N_FIELDS, 37) and np.array_equal(result.t, t_eval)
    # t_eval's states are the dense output's, as run_to's (which may start dopri5 with another trial
    # step: its first call's step); sol at the own steps is the run's own states there, bit for bit.
    run_to = simulator.Simulation(paper).run_to(t_eval)
    if integrator is GAUSS8_ADAPTIVE:
        assert np.array_equal(result.y.T, run_to)
    assert np.abs(result.y.T - run_to).max() < 1e-10
    assert np.array_equal(result.sol(result.t_steps), result.y_steps)
    assert np.array_equal(result.sol(t_eval[::-1]), result.y[:, ::-1])
    one = result.sol(2.0)
    assert one.shape == (N_FIELDS,) and one[FIELD["t"]] == 2.0
    assert abs(one[FIELD["chi"]] - 2.0) < 1e-9
    with pytest.raises(ValueError, match="outside the run"):
        result.sol(3.5)


def test_a_fixed_step_member_gives_its_schedule():
    short = scene("sine_steer_torque", {"name": "birkhoff_gauss4", "step_size": 0.01}, duration=0.5)
    result = simulator.solve(short, t_eval=[0.0, 0.1, 0.5])
    assert result.nsteps == 50 and result.t_steps.size == 51
    assert np.allclose(np.diff(result.t_steps), 0.01, rtol=0, atol=1e-15)
    sim = simulator.Simulation(short)
    assert np.array_equal(result.y_steps[:, 1:].T, sim.step(50, record=True))
    assert np.array_equal(result.y.T, simulator.Simulation(short).run_to([0.0, 0.1, 0.5]))
    with pytest.raises(ValueError, match="not one of the step schedule"):
        simulator.solve(short, t_eval=[0.105])


def test_bad_arguments_are_refused_by_name():
    paper = scene("paper_special", GAUSS8_ADAPTIVE)
    with pytest.raises(ValueError, match=r"t_eval\[1\]"):
        simulator.solve(paper, t_eval=[2.0, 1.9])
    with pytest.raises(ValueError, match=r"t_eval\[0\]"):
        simulator.solve(paper, t_eval=[0.0])
    with pytest.raises(TypeError, match=r"events\[0\]"):
        simulator.solve(paper, events=[1.0])
    bad = event(lambda t, s: 1.0)
    bad.terminal = "yes"
    with pytest.raises(TypeError, match="terminal"):
        simulator.solve(paper, events=bad)


def test_a_failing_step_ends_with_status_minus_one_and_the_states_before_it():
    # The paper's cart is singular at chi = pi: a run past t = pi fails there.
    paper = scene("paper_special", dict(GAUSS8_ADAPTIVE, position_tolerance=1e-8), duration=2.0)
    result = simulator.solve(paper, t_eval=np.linspace(paper.start_time, paper.start_time + 2.0, 201))
    assert result.status == -1 and not result.success and "singular" in result.message
    assert 0 < result.t.size < 201 and result.t[-1] < math.pi and result.nsteps > 0
    assert result.t_steps[-1] < math.pi
    print("failure:", result.message)


# --- events ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("integrator", [GAUSS8_ADAPTIVE, DOPRI5])
def test_crossings_are_located_to_1e_10_s_against_the_closed_form(integrator):
    paper = scene("paper_special", integrator)
    arc = event(lambda t, s: s[FIELD["pi1"]] - 1.3, direction=1.0)  # pi1 = 1.3 m at 2 atan(e^0.3)
    chi = event(lambda t, s: s[FIELD["chi"]] - 2.5)                   # chi = 2.5 rad at 2.5 s
    never = event(lambda t, s: s[FIELD["pi1"]] - 1.3, direction=-1.0)  # pi1 only grows
    result = simulator.solve(paper, events=[arc, chi, never])
    assert result.status == 0
    exact = [2 * math.atan(math.exp(0.3)), 2.5]
    errors = []
    for k in range(2):
        assert result.t_events[k].shape == (1,) and result.y_events[k].shape == (1, N_FIELDS)
        errors.append(abs(result.t_events[k][0] - exact[k]))
        assert result.y_events[k][0, FIELD["t"]] == result.t_events[k][0]
    assert result.t_events[2].size == 0 and result.y_events[2].shape == (0, N_FIELDS)
    assert abs(result.y_events[0][0, FIELD["pi1"]] - 1.3) < 1e-11
    print(f"{integrator['name']}: crossing time errors {errors[0]:.2e} s (pi1), {errors[1]:.2e} s (chi)")
    assert max(errors) <= 1e-10


def test_a_terminal_event_stops_the_run_there():
    paper = scene("paper_special", GAUSS8_ADAPTIVE)
    stop = event(lambda t, s: s[FIELD["chi"]] - 2.5, terminal=True)
    t_eval = np.linspace(paper.start_time, 3.0, 30)
    result = simulator.solve(paper, t_eval=t_eval, events=stop, dense_output=True)
    assert result.status == 1 and result.success and result.terminal_event == 0
    assert result.t_events[0].size == 1 and abs(result.t_events[0][0] - 2.5) <= 1e-10
    assert np.array_equal(result.t, t_eval[t_eval <= result.t_events[0][0]])
    assert result.t_steps[-1] == result.t_events[0][0]
    assert np.array_equal(result.y_steps[:, -1], result.y_events[0][0])
    assert result.sol.t_max == result.t_events[0][0]
    # The states before the stop are the uninterrupted run's.
    assert np.array_equal(result.y.T, simulator.Simulation(paper).run_to(result.t))


def test_a_count_as_terminal_stops_at_that_occurrence_and_direction_filters():
    # sine_steer_torque swings chi about 0: count its zero crossings, then stop at the third.
    sine = scene("sine_steer_torque", {"name": "birkhoff_gauss6", "step_control": "adaptive",
                                       "position_tolerance": 1e-10, "step_size": 0.05}, duration=20.0)
    both = event(lambda t, s: s[FIELD["chi"]])
    rising = event(lambda t, s: s[FIELD["chi"]], direction=1.0)
    whole = simulator.solve(sine, events=[both, rising])
    crossings, ups = whole.t_events
    assert crossings.size >= 4, crossings
    assert set(ups).issubset(set(crossings)) and 0 < ups.size < crossings.size
    assert np.all(np.abs(whole.y_events[0][:, FIELD["chi"]]) < 1e-9)
    third = event(lambda t, s: s[FIELD["chi"]], terminal=3)
    stopped = simulator.solve(sine, events=third)
    assert stopped.status == 1 and np.array_equal(stopped.t_events[0], crossings[:3])
    assert stopped.t[-1] == crossings[2]


def test_a_crossing_on_a_scene_without_closed_form_agrees_with_a_much_finer_run():
    # y of B passes 2 m on sine_steer_torque (at about 3.3 s, 16 m down the road, swinging): the
    # Gauss member at a position tolerance of 1e-10 m against dopri5 at 1e-14.
    def y_passes(t, s):
        return s[FIELD["y"]] - 2.0
    y_passes.direction = 1.0
    coarse = simulator.solve(scene("sine_steer_torque", {"name": "birkhoff_gauss8", "step_control": "adaptive",
                                                         "position_tolerance": 1e-10, "step_size": 0.1},
                                   duration=6.0), events=y_passes)
    fine = simulator.solve(scene("sine_steer_torque", {"name": "dopri5", "step_size": 0.001, "tolerance": 1e-14},
                                 duration=6.0), events=y_passes)
    assert coarse.t_events[0].size == 1 == fine.t_events[0].size
    difference = abs(coarse.t_events[0][0] - fine.t_events[0][0])
    assert 3.0 < fine.t_events[0][0] < 3.5
    assert abs(coarse.y_events[0][0, FIELD["y"]] - 2.0) < 1e-12
    print(f"y = 2 m at {fine.t_events[0][0]:.15f} s; gauss8 adaptive 1e-10 m vs dopri5 1e-14: {difference:.2e} s")
    assert difference <= 1e-10


def test_an_event_function_that_raises_ends_solve_with_its_error():
    def broken(t, s):
        if t > 2.0:
            raise ZeroDivisionError("from the event function")
        return 1.0
    with pytest.raises(ZeroDivisionError, match="from the event function"):
        simulator.solve(scene("paper_special", GAUSS8_ADAPTIVE), events=broken)


@pytest.mark.parametrize("member", ["birkhoff_gauss8", "birkhoff4"])
def test_the_reversible_control_whose_last_step_passes_the_end_gives_the_same_result(member):
    # const_steer_torque: the heading passes 1 rad at about 3.9 s. The reversible control's grid
    # steps past the run's end and leaves its last step by a side step: its own steps end there.
    def heading_passes(t, s):
        return s[FIELD["theta"]] - 1.0
    heading_passes.direction = 1.0
    reversible = scene("const_steer_torque", {"name": member, "step_control": "reversible",
                                              "position_tolerance": 1e-10, "step_size": 0.1}, duration=6.0)
    result = simulator.solve(reversible, events=heading_passes, dense_output=True)
    assert result.status == 0 and result.t_steps[-1] == 6.0 and np.all(np.diff(result.t_steps) > 0)
    assert result.nsteps == result.statistics["internal_steps"] and result.njev is None
    sim = simulator.Simulation(reversible)
    assert np.array_equal(sim.run_to([reversible.step_size, 6.0])[1], result.y[:, -1])
    assert np.array_equal(result.sol(result.t_steps), result.y_steps)
    fine = simulator.solve(scene("const_steer_torque", {"name": "dopri5", "step_size": 0.001, "tolerance": 1e-14},
                                 duration=6.0), events=heading_passes)
    difference = abs(result.t_events[0][0] - fine.t_events[0][0])
    print(f"{member} reversible: {result.nsteps} own steps, heading = 1 rad at {fine.t_events[0][0]:.12f} s, "
          f"{difference:.1e} s from dopri5 at 1e-14")
    assert 3.5 < fine.t_events[0][0] < 4.5 and difference <= 1e-10


def test_threads_each_solving_finish_as_one_thread_does():
    # solve() holds the GIL only for event functions: four threads, two with events and two
    # without, each end in the one-thread result; in a child with a timeout, so a hang fails.
    from test_simulator_hostile import run_child
    out = run_child("""
        import threading
        import numpy as np
        from birkhoff_cart import simulator
        F = {name: k for k, name in enumerate(simulator.STATE_FIELDS)}
        scene = simulator.load_scene("config/scenes/sine_steer_torque.yaml", {
            "reference": None, "duration": 4.0,
            "integrator": {"name": "birkhoff_gauss6", "step_control": "adaptive",
                           "position_tolerance": 1e-9, "step_size": 0.05}})
        def crossing(t, s):
            return s[F["chi"]]
        def work(k):
            result = simulator.solve(scene, events=crossing if k % 2 else None, dense_output=True)
            return result.y_steps, result.t_events, result.sol(np.linspace(0.0, 4.0, 9))
        expected = [work(0), work(1)]
        results = [None] * 4
        def run(k):
            results[k] = work(k)
        for attempt in range(3):
            threads = [threading.Thread(target=run, args=(k,), daemon=True) for k in range(4)]
            for t in threads: t.start()
            for t in threads: t.join()
            for k, (steps, events, dense) in enumerate(results):
                want = expected[k % 2]
                assert np.array_equal(steps, want[0]) and np.array_equal(dense, want[2])
                assert (events is None) == (want[1] is None)
                assert events is None or np.array_equal(events[0], want[1][0])
        print("ok", expected[1][1][0].size)
        """)
    assert out.startswith("ok") and int(out.split()[1]) >= 2


def test_at_fixed_steps_a_crossing_is_located_on_one_step_of_the_member_from_the_steps_start():
    # y of B passes 2 m on sine_steer_torque: birkhoff_gauss8 at h = 0.05 s against dopri5 at 1e-14.
    def y_passes(t, s):
        return s[FIELD["y"]] - 2.0
    y_passes.direction = 1.0
    def sine(integrator):
        return scene("sine_steer_torque", integrator, duration=6.0)
    fixed = simulator.solve(sine({"name": "birkhoff_gauss8", "step_size": 0.05}), events=y_passes)
    fine = simulator.solve(sine({"name": "dopri5", "step_size": 0.001, "tolerance": 1e-14}), events=y_passes)
    assert fixed.nsteps == 120 and fixed.t_events[0].size == 1
    difference = abs(fixed.t_events[0][0] - fine.t_events[0][0])
    print(f"birkhoff_gauss8 at h = 0.05 s: {difference:.1e} s from dopri5 at 1e-14")
    assert difference <= 1e-10
    assert abs(fixed.y_events[0][0, FIELD["y"]] - 2.0) < 1e-12
    # nfev counts the steps beside the run that located it; the run's own counts are the same as
    # without the event, and t_eval at fixed steps costs nothing (the schedule's states).
    plain = simulator.solve(sine({"name": "birkhoff_gauss8", "step_size": 0.05}), t_eval=[0.0, 3.0, 6.0])
    assert plain.nfev == plain.statistics["rhs_evaluations"]
    assert fixed.statistics["rhs_evaluations"] == plain.statistics["rhs_evaluations"] < fixed.nfev
    assert np.array_equal(plain.y, fixed.y_steps[:, [0, 60, 120]])
    # Terminal: the run and t_eval end at the crossing, which lies between two steps.
    y_passes.terminal = True
    t_eval = np.arange(0.0, 6.0001, 0.05)
    stopped = simulator.solve(sine({"name": "birkhoff_gauss8", "step_size": 0.05}), t_eval=t_eval, events=y_passes)
    assert stopped.status == 1 and stopped.t_events[0][0] == fixed.t_events[0][0]
    assert stopped.t_steps[-1] == stopped.t_events[0][0] and np.all(np.diff(stopped.t_steps) > 0)
    assert np.array_equal(stopped.y_steps[:, :-1], fixed.y_steps[:, :stopped.nsteps])
    assert stopped.t.size == np.count_nonzero(t_eval <= stopped.t_events[0][0])
    # A scene whose actuators move with the run cannot be stepped beside it: refused by name.
    with pytest.raises(ValueError, match="events at fixed steps: .*actuators"):
        simulator.solve(scene("steering_actuator"), events=y_passes)


def test_a_text_is_no_event_function():
    # Texts like 'chi=0.1' are the CLI's and the node's events; solve() takes callables (it would
    # otherwise iterate the text letter by letter).
    with pytest.raises(TypeError, match="got the text 'chi=0.1'"):
        simulator.solve(scene("paper_special", GAUSS8_ADAPTIVE), events="chi=0.1")


def test_a_g_that_stays_at_zero_has_no_crossing():
    result = simulator.solve(scene("paper_special", GAUSS8_ADAPTIVE), events=lambda t, state: 0.0)
    assert result.status == 0 and result.t_events[0].size == 0

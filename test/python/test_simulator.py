"""The Python module birkhoff_cart.simulator (docs/python.md): scenes from files, dicts and
overrides, with the scene reader's errors as SceneError naming the key; every registry member and
step control; steps with torque commands, one call or many, the same bit for bit; the time grid;
diagnostics and the accuracy guard's verdict as cart_simulate reports them; and the two checks of
the examples: the default scene's 60 s run ends where cart_simulate's does, bit for bit, and
scripts/python/race_cell.py prints the error `work_precision --measure` measures, to the last digit.

Run by scripts/run_tests.sh (catkin's run_tests: pytest-test_simulator.xml), or after
`source .ws/devel/setup.bash`: python3 -m pytest test/python.
"""
import csv
import json
import math
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

from birkhoff_cart import simulator

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "config" / "scenes"
# The package's executables: the devel space's (CMake passes it), else found beside the module.
BIN = pathlib.Path(os.environ.get("BIRKHOFF_CART_BIN_DIR",
                                  pathlib.Path(simulator.__file__).resolve().parents[3] / "birkhoff_cart"))
FIELD = {name: index for index, name in enumerate(simulator.STATE_FIELDS)}
DIAGNOSTIC = {name: index for index, name in enumerate(simulator.DIAGNOSTIC_FIELDS)}


def scene_path(name):
    return str(SCENES / f"{name}.yaml")


def short(scene_name, duration=0.5, **integrator):
    """The shipped scene `scene_name` cut to `duration` [s], its reference off, integrator keys replaced."""
    overrides = {"duration": duration, "reference": None}
    if integrator:
        overrides["integrator"] = integrator
    return simulator.load_scene(scene_path(scene_name), overrides)


# --- scenes ---------------------------------------------------------------------------------------

def test_a_scene_from_its_file_from_its_dict_and_from_a_path_object_runs_the_same():
    from_file = simulator.Simulation(short("sine_steer_torque"))
    document = simulator.scene_document(scene_path("sine_steer_torque"))
    document["duration"] = 0.5
    document.pop("reference", None)
    from_dict = simulator.Simulation(simulator.load_scene(document))
    from_path = simulator.Simulation(simulator.load_scene(SCENES / "sine_steer_torque.yaml",
                                                          {"duration": 0.5, "reference": None}))
    final = from_file.run()
    assert np.array_equal(final, from_dict.run())
    assert np.array_equal(final, from_path.run())
    assert from_file.scene.name == "sine_steer_torque" and from_dict.scene.name == "dict"


def test_overrides_merge_maps_replace_values_and_none_removes_a_key():
    scene = simulator.load_scene(scene_path("default"), {"integrator": {"name": "rk4", "step_size": 0.02},
                                                         "duration": 2.0, "reference": None})
    assert (scene.integrator, scene.step_size, scene.duration) == ("rk4", 0.02, 2.0)
    assert scene.output_rate == 100.0  # untouched keys stay
    assert scene.birkhoffian_form == "autonomous"


@pytest.mark.parametrize("source, overrides, key", [
    ("default", {"integrator": {"step_size": -0.01}}, "integrator.step_size"),
    ("default", {"integrator": {"name": "rk5"}}, "integrator.name"),
    ("default", {"effects": {"air_drag": {"coefficient": -1.0}}}, "effects.air_drag.coefficient"),
    ("default", {"duration": float("nan")}, "duration"),
    ("default", {"cart": {"wheel_base": 1.0}}, "cart.wheel_base"),
    ("free_coast", {"integrator": {"step_control": "reversible"}}, "integrator.position_tolerance"),
    ({"description": "no cart"}, None, "cart"),
])
def test_scene_errors_are_value_errors_naming_the_key_as_the_cli_does(source, overrides, key):
    with pytest.raises(simulator.SceneError) as raised:
        simulator.load_scene(scene_path(source) if isinstance(source, str) else source, overrides)
    error = raised.value
    assert isinstance(error, ValueError)
    assert error.key == key, str(error)
    assert f"key '{key}'" in str(error)
    if key == "integrator.name":  # the known names, as the CLI lists them
        assert "'rk5' is not one of: birkhoff2, birkhoff4, rk2, rk4" in str(error)


def test_the_cli_reports_the_same_scene_error(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text((SCENES / "default.yaml").read_text().replace("step_size: 1.0e-2", "step_size: -1.0e-2", 1))
    cli = subprocess.run([str(BIN / "cart_simulate"), "--scene", str(bad), "--output", str(tmp_path / "out.csv")],
                         capture_output=True, text=True)
    assert cli.returncode == 3
    with pytest.raises(simulator.SceneError) as raised:
        simulator.load_scene(str(bad))
    assert cli.stderr.strip() == f"cart_simulate: {raised.value}"
    assert raised.value.file == str(bad)


def test_a_value_a_scene_cannot_hold_and_a_missing_file_are_named():
    with pytest.raises(TypeError, match="integrator.name"):
        simulator.load_scene(scene_path("default"), {"integrator": {"name": object()}})
    with pytest.raises(simulator.SceneError) as raised:
        simulator.load_scene(scene_path("no_such_scene"))
    assert raised.value.key == "(file)"


# --- members and controls -------------------------------------------------------------------------

def test_the_registry_is_the_cli_s():
    members = simulator.integrators()
    names = [member["name"] for member in members]
    help_text = subprocess.run([str(BIN / "cart_simulate"), "--help"], capture_output=True, text=True).stdout
    for member in members:
        assert f"  {member['name']} " in help_text
    assert "birkhoff_gauss4" in names and "dopri5" in names and len(names) == len(set(names)) >= 12
    birkhoffian = {member["name"] for member in members if member["kind"] in ("Birkhoffian collocation", "composition")}
    assert {member["name"] for member in members if member["reversible"]} == {
        name for name in birkhoffian if next(m for m in members if m["name"] == name)["symmetric"]}
    # The adaptive control takes the Gauss members and dopri5; the compositions and birkhoff2, whose
    # estimates do not follow their error, are refused under it (accuracy.md §4.4).
    adaptive = {member["name"] for member in members if member["adaptive"]}
    assert adaptive == {name for name in birkhoffian if name.startswith("birkhoff_gauss")} | {"dopri5"}


def test_the_rejected_steps_are_the_cli_s(tmp_path):
    # The rejected attempts of a step control, as cart_simulate's summary counts them ("N rejected").
    scene = simulator.load_scene(scene_path("paper_special"), {"reference": None, "integrator": {
        "name": "birkhoff_gauss8", "step_control": "adaptive", "position_tolerance": 1e-3, "step_size": 0.1}})
    simulation = simulator.Simulation(scene)
    simulation.run()
    counts = simulation.statistics()
    cli = subprocess.run([str(BIN / "cart_simulate"), "--scene", scene_path("paper_special"), "--integrator",
                          "birkhoff_gauss8", "--step-control", "adaptive", "--position-tolerance", "1e-3",
                          "--output-rate", "10", "--output", str(tmp_path / "out.csv")],
                         capture_output=True, text=True)
    summary = re.search(r"(\d+) internal steps .*, (\d+) rejected", cli.stdout)
    assert summary, cli.stdout
    assert (counts["internal_steps"], counts["rejected_steps"]) == (int(summary[1]), int(summary[2]))
    assert counts["rejected_steps"] > 0  # paper_special rejects at 1e-3 m (accuracy.md §4.3)


def test_the_global_error_estimate_is_in_the_statistics_when_asked_for():
    settings = dict(name="birkhoff_gauss6", step_size=0.1, step_control="adaptive", position_tolerance=1e-7)
    plain = simulator.Simulation(short("jackknife_whirl", 4.0, **settings))
    estimated = simulator.Simulation(short("jackknife_whirl", 4.0, global_error_estimate=True, **settings))
    assert np.array_equal(plain.run(), estimated.run())  # the same steps and rows
    assert math.isnan(plain.statistics()["global_error_estimate"])
    assert not plain.statistics()["global_error_estimate_in_range"]
    # The whirl's error at 1e-7 m is 6.7e-9 m (against gauss8 at a fixed 1 ms step); the estimate is
    # within its band of it ([0.5, 10]×, accuracy.md §4.5): 1.4e-8 m.
    assert 0.5 * 6.7e-9 < estimated.statistics()["global_error_estimate"] < 10 * 6.7e-9
    assert estimated.statistics()["global_error_estimate_in_range"]
    assert estimated.statistics()["rhs_evaluations"] > plain.statistics()["rhs_evaluations"]
    with pytest.raises(simulator.SceneError) as raised:
        short("jackknife_whirl", 4.0, name="birkhoff_gauss6", step_size=0.1, global_error_estimate=True)
    assert raised.value.key == "integrator.global_error_estimate"


@pytest.mark.parametrize("member", [member["name"] for member in simulator.integrators()])
def test_every_member_runs_at_fixed_steps_and_under_each_control_it_takes(member):
    row = next(m for m in simulator.integrators() if m["name"] == member)
    simulation = simulator.Simulation(short("sine_steer_torque", 0.2, name=member, step_size=0.01))
    final = simulation.run()
    assert simulation.at_end and final[FIELD["t"]] == 0.2 and np.all(np.isfinite(final))
    assert simulation.integrator == member
    for control, takes_it in (("reversible", row["reversible"]), ("adaptive", row["adaptive"])):
        if takes_it:
            controlled = simulator.Simulation(short("jackknife_whirl", 1.0, name=member, step_size=0.5,
                                                    step_control=control, position_tolerance=1e-5))
            assert np.all(np.isfinite(controlled.run())), control
            assert controlled.statistics()["internal_steps"] > 2, control
        else:
            with pytest.raises(simulator.SceneError) as raised:
                short("jackknife_whirl", 1.0, name=member, step_size=0.5, step_control=control,
                      position_tolerance=1e-5)
            assert raised.value.key.startswith("integrator."), control


# --- stepping -------------------------------------------------------------------------------------

def test_batches_single_steps_and_one_run_end_in_the_same_state():
    scene = short("default", 1.0)
    whole = simulator.Simulation(scene).run()
    batches = simulator.Simulation(scene)
    while not batches.at_end:
        batches.step(37)
    singles = simulator.Simulation(scene)
    for _ in range(100):
        singles.step()
    assert np.array_equal(whole, batches.state()) and np.array_equal(whole, singles.state())
    assert batches.steps_taken == 100
    with pytest.raises(simulator.EndOfRunError):  # at the end: no further step
        batches.step(5)
    assert batches.steps_taken == 100 and np.array_equal(batches.state(), whole)


def test_torque_commands_per_step_equal_one_command_a_call_and_are_held():
    scene = short("driven", 0.3)
    steering = np.linspace(-3.0, 3.0, 300)
    drive = np.full(300, 12.0)
    batched = simulator.Simulation(scene)
    recorded = batched.step(300, steering_torque=steering, drive_torque=drive, record=True)
    one_by_one = simulator.Simulation(scene)
    for k in range(300):
        state = one_by_one.step(1, steering_torque=float(steering[k]), drive_torque=12.0 if k == 0 else None)
        assert np.array_equal(state, recorded[k])
    assert recorded.shape == (300, len(simulator.STATE_FIELDS))
    assert np.array_equal(recorded[-1], batched.state())
    assert batched.steering_command == steering[-1] and one_by_one.drive_command == 12.0  # held
    start_speed = simulator.Simulation(scene).state()[FIELD["omega1"]]
    assert batched.state()[FIELD["omega1"]] > start_speed  # the drive torque pushed


def test_bad_commands_are_refused_by_name_and_nothing_moves():
    simulation = simulator.Simulation(short("driven", 0.3))
    with pytest.raises(ValueError, match="steering_torque"):
        simulation.step(3, steering_torque=[1.0, 2.0])
    with pytest.raises(ValueError, match="NaN"):
        simulation.step(2, drive_torque=[1.0, float("nan")])
    with pytest.raises(ValueError, match="count"):
        simulation.step(-1)
    with pytest.raises(ValueError, match="finite"):
        simulation.step(1, steering_torque=float("nan"))
    assert simulation.steps_taken == 0
    simulation.step(0, steering_torque=np.float64(4.5), drive_torque=np.int64(3))  # numpy scalars; commands only
    assert (simulation.steering_command, simulation.drive_command, simulation.steps_taken) == (4.5, 3.0, 0)
    no_commands = simulator.Simulation(short("free_coast", 0.1))
    assert not no_commands.accepts_steering_command
    with pytest.raises(RuntimeError, match="steering_torque effect with source 'command'"):
        no_commands.step(1, steering_torque=1.0)
    assert no_commands.steps_taken == 0


def test_a_failed_step_raises_step_error_and_keeps_the_last_good_state():
    simulation = simulator.Simulation(short("jackknife_whirl", 2.0, name="birkhoff_gauss4", step_size=0.5,
                                            max_newton_iterations=1))
    before = simulation.state()
    with pytest.raises(simulator.StepError) as raised:
        simulation.step(4)
    assert isinstance(raised.value, RuntimeError)
    assert "step 1 of this call's 4" in str(raised.value)
    assert np.array_equal(simulation.state(), before) and simulation.steps_taken == 0


def test_reset_starts_the_run_again():
    simulation = simulator.Simulation(short("sine_steer_torque", 0.5))
    first = simulation.run()
    simulation.reset()
    assert simulation.steps_taken == 0 and simulation.time == 0.0
    assert np.array_equal(simulation.run(), first)


# --- the time grid --------------------------------------------------------------------------------

def test_run_to_returns_the_states_of_the_step_grid_with_their_diagnostics():
    scene = short("sine_steer_torque", 1.0)  # h = 1 ms
    times = np.linspace(0.0, 1.0, 11)
    states, diagnostics = simulator.Simulation(scene).run_to(times, diagnostics=True)
    stepped = simulator.Simulation(scene)
    for j, time in enumerate(times):
        while stepped.time < time - 1e-12:
            stepped.step()
        assert np.array_equal(states[j], stepped.state())
        assert np.array_equal(diagnostics[j], stepped.diagnostics(), equal_nan=True)
    assert states.shape == (11, len(simulator.STATE_FIELDS))
    assert diagnostics.shape == (11, len(simulator.DIAGNOSTIC_FIELDS))


@pytest.mark.parametrize("integrator", [{"name": "dopri5", "step_size": 0.01, "tolerance": 1e-12},
                                        {"name": "birkhoff_gauss6", "step_size": 0.1, "step_control": "adaptive",
                                         "position_tolerance": 1e-10}])
def test_a_member_with_its_own_steps_gives_any_instant_from_its_dense_output(integrator):
    # Instants off the output grid (h = 0.01 s, 0.1 s), against a fine fixed-step run that has them on
    # its grid (birkhoff_gauss8 at 0.1 ms); then the run goes on only through run_to() and run().
    scene = short("sine_steer_torque", 1.0, **integrator)
    times = [0.0015, 0.3337, 0.5]
    dense = simulator.Simulation(scene)
    states = dense.run_to(times)
    assert list(states[:, FIELD["t"]]) == times
    fine = simulator.Simulation(short("sine_steer_torque", 1.0, name="birkhoff_gauss8", step_size=1e-4))
    difference = np.abs(states - fine.run_to(times))[:, FIELD["x"]:FIELD["omega2"] + 1].max()
    print(f"{integrator['name']}: dense output against gauss8 at 0.1 ms: {difference:.3e}")
    assert difference < 1e-8
    with pytest.raises(RuntimeError, match="continue with run_to"):
        dense.step(1)
    assert dense.run()[FIELD["t"]] == 1.0 and dense.at_end
    dense.reset()
    assert dense.step(10)[FIELD["t"]] == pytest.approx(10 * scene.step_size)  # on its step grid again


def test_run_to_refuses_a_time_off_the_grid_in_the_past_or_beyond_the_end_before_stepping():
    simulation = simulator.Simulation(short("sine_steer_torque", 1.0))
    for times, words in [([0.2, 0.2005], "not one of the step schedule's instants"),
                         ([0.3, 1.5], "not one of the step schedule's instants"),
                         ([0.4, 0.3], "must increase")]:
        with pytest.raises(ValueError, match=words):
            simulation.run_to(times)
        assert simulation.steps_taken == 0
    simulation.run_to([0.5])
    with pytest.raises(ValueError, match="in the past"):
        simulation.run_to([0.25])


# --- diagnostics and the accuracy guard ------------------------------------------------------------

def test_diagnostics_are_the_balances_of_the_state():
    simulation = simulator.Simulation(short("drive_rr_drag", 1.0))
    simulation.run()
    d = simulation.diagnostics()
    energy0 = simulator.Simulation(short("drive_rr_drag", 1.0)).diagnostics()[DIAGNOSTIC["energy"]]
    work = simulation.state()[FIELD["applied_work"]]
    assert math.isclose(d[DIAGNOSTIC["energy_balance_residual"]], d[DIAGNOSTIC["energy"]] - energy0 - work,
                        rel_tol=0, abs_tol=1e-12)
    assert abs(d[DIAGNOSTIC["energy_balance_residual"]]) < 1e-6 * d[DIAGNOSTIC["energy"]]
    assert d[DIAGNOSTIC["local_error_estimate"]] > 0  # gauss4 keeps one
    assert math.isnan(d[DIAGNOSTIC["reference_position_error"]])  # no reference in this scene


def test_the_accuracy_verdict_is_cart_simulate_s(tmp_path):
    # jackknife_whirl with a 2 cm wheelbase, run with rk4: the guard's ERROR (accuracy_guard_test).
    text = (SCENES / "jackknife_whirl.yaml").read_text()
    text = text.replace("wheelbase: 1.05 ", "wheelbase: 0.02 ", 1).replace("name: birkhoff2 ", "name: rk4 ", 1)
    path = tmp_path / "short_wheelbase_whirl.yaml"
    path.write_text(text)
    cli = subprocess.run([str(BIN / "cart_simulate"), "--scene", str(path), "--quiet", "--on-accuracy-error", "warn",
                          "--output", str(tmp_path / "out.csv")], capture_output=True, text=True)
    cli_verdict = next(line for line in cli.stdout.splitlines() if line.strip().startswith("accuracy:"))
    simulation = simulator.Simulation(simulator.load_scene(str(path)))
    while not simulation.at_end:
        simulation.step(1000)
    verdict = simulation.accuracy()
    assert verdict["level"] == "ERROR"
    assert cli_verdict.strip() == f"accuracy: {verdict['summary']}"
    assert verdict["largest"][verdict["quantities"].index("energy_balance_relative")] > 1e-2
    healthy = simulator.Simulation(short("jackknife_whirl", 5.0))
    healthy.run()
    assert healthy.accuracy()["level"] == "OK"


# --- the examples' checks -------------------------------------------------------------------------

def test_the_default_scene_s_60_s_run_ends_where_cart_simulate_s_does_bit_for_bit(tmp_path):
    output = tmp_path / "default.csv"
    subprocess.run([str(BIN / "cart_simulate"), "--scene", scene_path("default"), "--quiet", "--output", str(output)],
                   check=True, capture_output=True)
    with open(output) as rows:
        last = list(csv.DictReader(rows))[-1]
    script = subprocess.run([sys.executable, str(REPO / "scripts" / "python" / "default_scene.py"), scene_path("default")],
                            check=True, capture_output=True, text=True)
    assert script.stdout.strip().splitlines()[-1] == ",".join(
        last[column] for column in ("t", "x", "y", "theta", "chi", "phi1", "phi2", "phi3", "phi4", "pi1", "omega1",
                                    "omega2", "energy", "p2"))


@pytest.mark.parametrize("method, step", [("birkhoff_gauss4", 0.2), ("birkhoff8_kahan_li", 0.1), ("rk4", 0.05)])
def test_race_cell_py_prints_the_error_work_precision_measures(tmp_path, method, step):
    work_precision = str(BIN / "work_precision")
    scene = scene_path("sine_steer_torque")
    reference = tmp_path / "reference.csv"
    subprocess.run([work_precision, "--reference-run", "--scene", scene, "--duration", "6", "--reference-kind",
                    "dopri5", "--output", str(reference)], check=True, capture_output=True)
    measured = subprocess.run([work_precision, "--measure", "--scene", scene, "--duration", "6", "--method", method,
                               "--step", str(step), "--reference-file", str(reference), "--repetitions", "1"],
                              check=True, capture_output=True, text=True)
    expected = json.loads(measured.stdout)["position_error_m"]
    script = subprocess.run([sys.executable, str(REPO / "scripts" / "python" / "race_cell.py"), scene, str(reference),
                             method, str(step), "6"], check=True, capture_output=True, text=True)
    assert float(script.stdout) == expected  # every digit: the same double

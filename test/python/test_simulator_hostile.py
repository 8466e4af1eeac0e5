"""birkhoff_cart.simulator against hostile calls (docs/python.md, "Limits and errors"): threads with
their own and with one shared Simulation, a recording beyond the memory bound, dicts that hold
themselves or nest without end, text that is not UTF-8, a directory, a bytes path, scenes beyond
the size cap, a string for a torque, a step past the end. Each ends in a named exception (or runs)
within seconds: no signal, no hang, nothing computed lost.

The thread cases run in a child process with a timeout, so that a deadlock (which holds the GIL)
fails the case instead of hanging the suite; faulthandler prints the child's stacks if it hangs.

Run by scripts/run_tests.sh (catkin's run_tests: pytest-test_simulator_hostile.xml), or after
`source .ws/devel/setup.bash`: python3 -m pytest test/python.
"""
import os
import pathlib
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from birkhoff_cart import simulator

from test_simulator import FIELD, REPO, SCENES, scene_path, short  # the scene helpers of the module's tests

CHILD_BUDGET = 120  # seconds a thread scenario may take before it counts as hung [s]


def run_child(script):
    """Runs `script` in a fresh Python with this module on its path; its stdout, or a failure on a hang."""
    program = "import faulthandler, sys\nfaulthandler.dump_traceback_later(%d, exit=True)\n" % (CHILD_BUDGET - 10)
    program += textwrap.dedent(script)
    try:
        done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=CHILD_BUDGET,
                              env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)), cwd=REPO)
    except subprocess.TimeoutExpired:
        pytest.fail("the child hung for %d s" % CHILD_BUDGET)
    assert done.returncode == 0, "child exit %d (a negative one is a signal):\n%s" % (done.returncode, done.stderr)
    return done.stdout


# --- threads --------------------------------------------------------------------------------------

def test_threads_each_with_its_own_simulation_finish_as_one_thread_does():
    # They hung 5 of 5: one thread held the GIL waiting for numpy's C API table (a function-local
    # static) while the thread initialising it waited for the GIL inside its import.
    out = run_child("""
        import threading
        import numpy as np
        from birkhoff_cart import simulator
        overrides = {"duration": 0.5, "reference": None}
        expected = simulator.Simulation(simulator.load_scene("config/scenes/driven.yaml", overrides)).run()
        results = [None] * 4
        def work(k):
            sim = simulator.Simulation(simulator.load_scene("config/scenes/driven.yaml", overrides))
            rows = [sim.step(10, record=True) for _ in range(50)]
            results[k] = (np.vstack(rows), sim.state())
        for attempt in range(5):
            threads = [threading.Thread(target=work, args=(k,), daemon=True) for k in range(4)]
            for t in threads: t.start()
            for t in threads: t.join()
            assert all(np.array_equal(final, expected) and len(rows) == 500 for rows, final in results)
        print("ok")
        """)
    assert out.strip() == "ok"


def test_threads_sharing_one_simulation_take_turns():
    # They hung 4 of 4 (two threads stepping one run at once). Now each call holds the run's lock:
    # the steps add up, and the run ends where one thread's does.
    out = run_child("""
        import threading
        import numpy as np
        from birkhoff_cart import simulator
        scene = simulator.load_scene("config/scenes/driven.yaml", {"duration": 2.0, "reference": None})
        shared = simulator.Simulation(scene)
        alone = simulator.Simulation(scene)
        alone.step(4 * 100 * 5)
        def work():
            for _ in range(100):
                shared.step(5)
                shared.state(); shared.diagnostics(); shared.time; shared.accuracy()
        threads = [threading.Thread(target=work, daemon=True) for _ in range(4)]
        for t in threads: t.start()
        for t in threads: t.join()
        assert shared.steps_taken == 2000, shared.steps_taken
        assert np.array_equal(shared.state(), alone.state())
        print("ok")
        """)
    assert out.strip() == "ok"


# --- the memory bound and what a failing call keeps ------------------------------------------------

def test_a_recording_beyond_the_memory_bound_is_refused_before_any_step():
    # step(10**9, record=True) grew until MemoryError after 4 194 305 steps, all recorded states lost.
    simulation = simulator.Simulation(short("driven", 5000.0))  # 5 000 000 steps of 1 ms
    started = time.monotonic()
    with pytest.raises(ValueError, match=r"would return 5000000 states .* beyond the bound of 1048576 states"):
        simulation.step(10**9, record=True)
    print("step(10**9, record=True) refused in %.3f s" % (time.monotonic() - started))
    assert simulation.steps_taken == 0
    with pytest.raises(ValueError, match="MAX_RECORDED_STATES"):
        simulation.run_to(np.arange(simulator.MAX_RECORDED_STATES + 1) * 1e-3)
    assert simulation.steps_taken == 0
    assert simulator.MAX_RECORDED_STATES == 2**20
    short_run = simulator.Simulation(short("driven", 0.1))  # the steps left count, not the count asked
    assert short_run.step(10**9, record=True).shape == (100, len(simulator.STATE_FIELDS))


def failing_step_scene():
    """driven under birkhoff_gauss4 at 0.1 s whose steering torque jumps to 1e6 N·m at 0.75 s: the
    step from 0.7 s fails (its stage solve does not converge in 2 Newton iterations)."""
    return simulator.load_scene(scene_path("driven"), {
        "duration": 2.0, "reference": None,
        "integrator": {"name": "birkhoff_gauss4", "step_size": 0.1, "max_newton_iterations": 2},
        "effects": {"steering_torque": {"profile": "step", "initial": 0.0, "final": 1e6, "step_time": 0.75,
                                        "value": None}}})


def test_a_failed_step_keeps_the_states_recorded_before_it():
    probe = simulator.Simulation(failing_step_scene())
    with pytest.raises(simulator.StepError):
        probe.step(20)
    good = probe.steps_taken
    assert 0 < good < 20, good  # the scene fails after some good steps: else the case checks nothing
    simulation = simulator.Simulation(failing_step_scene())
    with pytest.raises(simulator.StepError, match="step %d of this call's 20" % (good + 1)) as raised:
        simulation.step(20, record=True)
    assert raised.value.states.shape == (good, len(simulator.STATE_FIELDS))
    assert np.array_equal(raised.value.states[-1], simulation.state())  # the last good step, kept
    again = simulator.Simulation(failing_step_scene())
    times = np.arange(1, 20) * 0.1
    with pytest.raises(simulator.StepError) as raised:
        again.run_to(times)
    assert raised.value.states.shape == (good, len(simulator.STATE_FIELDS))
    assert np.array_equal(raised.value.states[-1], again.state())


# --- dicts that hold themselves or nest without end --------------------------------------------------

def test_a_dict_that_holds_itself_is_refused_by_its_key():
    # Killed Python with SIGSEGV (as a scene and inside the overrides).
    scene = simulator.scene_document(scene_path("default"))
    scene["integrator"]["loop"] = scene
    with pytest.raises(simulator.SceneError, match="key 'integrator.loop': holds the map or list at '.document.'"
                                                   " that holds it: a cycle") as raised:
        simulator.load_scene(scene)
    assert raised.value.key == "integrator.loop"
    overrides = {"integrator": {}}
    overrides["integrator"]["again"] = [overrides["integrator"]]
    with pytest.raises(simulator.SceneError, match="a cycle") as raised:
        simulator.load_scene(scene_path("default"), overrides)
    assert raised.value.key == "integrator.again[0]"
    assert raised.value.file.endswith("default.yaml with overrides")
    shared = {"value": 1.0}  # the same dict twice is no cycle: refused only as the unknown key it is
    with pytest.raises(simulator.SceneError, match="unknown key"):
        simulator.load_scene(scene_path("default"), {"x": shared, "y": shared})


@pytest.mark.parametrize("depth", [65, 10_000, 100_000])
def test_a_dict_nested_beyond_the_depth_cap_is_refused_by_its_key(depth):
    # 100 000 deep: SIGSEGV; 10 000 deep: 21 s and 310 MB, then a line and column that do not exist.
    deep = leaf = {}
    for _ in range(depth - 1):
        leaf["a"] = {}
        leaf = leaf["a"]
    started = time.monotonic()
    with pytest.raises(simulator.SceneError, match="deeper than the cap of 64 levels") as raised:
        simulator.load_scene(deep)
    print("%d levels refused in %.3f s" % (depth, time.monotonic() - started))
    assert raised.value.key == ".".join(["a"] * 64)
    assert simulator.MAX_SCENE_DEPTH == 64


def test_a_file_nested_beyond_the_depth_cap_is_refused_by_its_key(tmp_path):
    deep = tmp_path / "deep.yaml"
    deep.write_text("cart: " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(simulator.SceneError, match="deeper than the cap") as raised:
        simulator.load_scene(deep)
    assert raised.value.key == "cart" + "[0]" * 63


# --- errors of the right type -------------------------------------------------------------------------

def test_text_that_is_not_utf8_is_a_scene_error_naming_the_key(tmp_path):
    # A byte that is not UTF-8 in a key raised UnicodeDecodeError.
    bad = tmp_path / "bad_key.yaml"
    bad.write_bytes(pathlib.Path(scene_path("default")).read_bytes().replace(b"wheelbase:", b"wheel\xffbase:", 1))
    with pytest.raises(simulator.SceneError, match=r"is not UTF-8 text") as raised:
        simulator.load_scene(bad)
    assert raised.value.key == "cart.wheel\\xffbase"
    with pytest.raises(simulator.SceneError, match="is not UTF-8 text") as raised:
        simulator.load_scene(scene_path("default"), {"integrator": {"na\udcffme": "rk4"}})
    assert raised.value.key == "integrator.'na\\udcffme'"
    with pytest.raises(simulator.SceneError, match="is not UTF-8 text") as raised:
        simulator.load_scene(scene_path("default"), {"description": "caf\udce9"})
    assert raised.value.key == "description"


def test_a_directory_is_a_scene_error_saying_so():
    # Raised RuntimeError: basic_filebuf::underflow.
    with pytest.raises(simulator.SceneError, match="key '.file.': is a directory, not a scene file") as raised:
        simulator.load_scene(SCENES)
    assert raised.value.file == str(SCENES)
    with pytest.raises(simulator.SceneError, match="is a directory"):
        simulator.scene_document(str(SCENES))


def test_a_bytes_path_reads_and_is_named_as_text(tmp_path):
    # Named as b'...'.
    assert simulator.load_scene(os.fsencode(scene_path("default"))).name == "default"
    missing = os.fsencode(str(tmp_path / "caf\xe9.yaml"))
    with pytest.raises(simulator.SceneError) as raised:
        simulator.load_scene(missing)
    assert "b'" not in str(raised.value) and os.fsdecode(missing) in str(raised.value)
    assert raised.value.file == os.fsdecode(missing)
    with pytest.raises(simulator.SceneError, match=r"caf\\xff.yaml"):  # undecodable bytes as \xNN
        simulator.load_scene(os.fsencode(str(tmp_path)) + b"/caf\xff.yaml")


def test_scenes_beyond_the_size_cap_are_refused_before_they_are_parsed(tmp_path):
    # A 10 MB scene kept Python busy 16 s before refusing it.
    big = tmp_path / "big.yaml"
    with open(big, "w") as f:
        f.write(pathlib.Path(scene_path("default")).read_text())
        f.write(("# " + "x" * 98 + "\n") * 100_000)
    started = time.monotonic()
    with pytest.raises(simulator.SceneError, match=r"key '\(file\)': is 10\d{6} bytes, beyond the cap of 1048576"
                                                   r" bytes of a scene \(refused before reading\)"):
        simulator.load_scene(big)
    print("10 MB scene file refused in %.4f s" % (time.monotonic() - started))
    with pytest.raises(simulator.SceneError, match="beyond the cap"):
        simulator.scene_document(big)
    document = simulator.scene_document(scene_path("default"))
    document["description"] = "x" * (10 * 2**20)  # a dict whose document passes the cap
    started = time.monotonic()
    with pytest.raises(simulator.SceneError, match=r"key 'description': takes the document beyond the cap of"
                                                   r" 1048576 bytes of a scene"):
        simulator.load_scene(document)
    print("10 MB dict refused in %.4f s" % (time.monotonic() - started))
    from birkhoff_cart_study.scenes import MAX_SCENE_BYTES  # the study runner's cap (conftest puts src/ on the path)
    assert simulator.MAX_SCENE_BYTES == MAX_SCENE_BYTES == 2**20


@pytest.mark.parametrize("torque", ["1", b"1", ["1.0"], True, object(), {"a": 1}])
def test_a_torque_that_is_not_a_number_is_a_type_error_naming_it(torque):
    # "1" was taken as 1.0.
    simulation = simulator.Simulation(short("driven", 0.1))
    with pytest.raises(TypeError, match="steering_torque must be None, a number"):
        simulation.step(1, steering_torque=torque)
    with pytest.raises(TypeError, match="drive_torque must be None, a number"):
        simulation.step(1, drive_torque=torque)
    assert simulation.steps_taken == 0


def test_a_step_at_the_end_raises_end_of_run_error():
    # Returned silently: as scipy's solvers, a step of a finished run raises (a RuntimeError).
    simulation = simulator.Simulation(short("driven", 0.1))
    final = simulation.run()
    with pytest.raises(simulator.EndOfRunError, match=r"step\(5\): the run is at its end, t = 0.1 s, after 100 steps"):
        simulation.step(5)
    assert issubclass(simulator.EndOfRunError, RuntimeError)
    assert np.array_equal(simulation.state(), final) and simulation.steps_taken == 100
    simulation.step(0, steering_torque=1.0)  # a command alone moves nothing: allowed
    assert np.array_equal(simulation.run(), final)  # run() at the end returns the final state
    simulation.reset()
    assert simulation.step(5)[FIELD["t"]] == pytest.approx(0.005)

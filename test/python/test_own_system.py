"""Your own Birkhoffian system from Python (docs/python.md, "Your own Birkhoffian system"):
simulator.BirkhoffianSystem integrated by every Birkhoffian member at fixed steps and by the Gauss
members under both step controls. A pendulum (canonical, identity chart) and a damped oscillator
(the seed paper's e^{γt} form, in its own Darboux chart and in the identity chart) against their
references: the order of each member, the pendulum's energy, the tolerance of the controls; the
Chaplygin sleigh written in Python against the same sleigh of the C++ core; and bad requests
refused by name.

Run by scripts/run_tests.sh (catkin's run_tests: pytest-test_own_system.xml), or after
`source .ws/devel/setup.bash`: python3 -m pytest test/python/test_own_system.py.
"""
import math

import numpy as np
import pytest

from birkhoff_cart import simulator

# --- the systems ----------------------------------------------------------------------------------

def pendulum(**extra):
    """q'' = -sin q: z = (q [rad], p [1/s]), B = H = p²/2 - cos q, K = K₀ (the default)."""
    return simulator.BirkhoffianSystem(2, birkhoffian_gradient=lambda z, t: (math.sin(z[0]), z[1]), **extra)


def pendulum_energy(y):
    return 0.5 * y[1] ** 2 - np.cos(y[0])


GAMMA = 0.2   # c/m [1/s]
STIFFNESS = 1.0  # k/m [1/s²]


def damped_oscillator_in_its_chart():
    """q'' = -k q - γ q' (m = 1) in the paper's form R = e^{γt}(p, 0), B = e^{γt}(p²/2 + k q²/2):
    K = e^{γt} K₀, Darboux chart w = (q, e^{γt} p), in which it is Hamiltonian."""
    to_darboux = lambda z, t: (z[0], math.exp(GAMMA * t) * z[1])
    from_darboux = lambda w, t: (w[0], math.exp(-GAMMA * t) * w[1])
    rates = lambda w, t: (math.exp(-GAMMA * t) * w[1], -STIFFNESS * math.exp(GAMMA * t) * w[0])
    return simulator.BirkhoffianSystem(2, darboux_chart=(to_darboux, from_darboux, rates))


def damped_oscillator_in_z():
    """The same R and B given as K(t), ∇B and ∂R/∂t: the members step in z (identity chart)."""
    e = lambda t: math.exp(GAMMA * t)
    return simulator.BirkhoffianSystem(
        2,
        structure_matrix=lambda z, t: e(t) * np.array([[0.0, -1.0], [1.0, 0.0]]),
        birkhoffian_gradient=lambda z, t: (e(t) * STIFFNESS * z[0], e(t) * z[1]),
        birkhoff_functions_time_derivative=lambda z, t: (GAMMA * e(t) * z[1], 0.0))


def damped_oscillator_exact(t, q0=1.0, p0=0.0):
    """(q, p) of q'' + γ q' + k q = 0 from (q0, p0) at 0 (underdamped)."""
    omega = math.sqrt(STIFFNESS - GAMMA ** 2 / 4)
    a, b = q0, (p0 + GAMMA / 2 * q0) / omega
    decay = math.exp(-GAMMA * t / 2)
    q = decay * (a * math.cos(omega * t) + b * math.sin(omega * t))
    p = decay * (-GAMMA / 2 * (a * math.cos(omega * t) + b * math.sin(omega * t))
                 + omega * (-a * math.sin(omega * t) + b * math.cos(omega * t)))
    return np.array([q, p])


PENDULUM_START = np.array([2.0, 0.0])  # swings to ±2 rad: far from the linear pendulum
PENDULUM_END = 6.0                     # [s]


@pytest.fixture(scope="module")
def pendulum_reference():
    """z at PENDULUM_END from gauss8 at h = 2.5 ms, checked against h = 5 ms."""
    fine = simulator.integrate(pendulum(), PENDULUM_START, (0.0, PENDULUM_END), "birkhoff_gauss8", step_size=0.0025)
    coarse = simulator.integrate(pendulum(), PENDULUM_START, (0.0, PENDULUM_END), "birkhoff_gauss8", step_size=0.005)
    assert np.max(np.abs(fine.y[:, -1] - coarse.y[:, -1])) < 1e-13
    return fine.y[:, -1]


# step sizes [s] of each member's order check: errors well above round-off, in the asymptotic range
ORDER_STEPS = {
    "birkhoff2": 0.02, "birkhoff4": 0.05, "birkhoff_gauss4": 0.1, "birkhoff_gauss6": 0.2, "birkhoff_gauss8": 0.4,
    "birkhoff4_suzuki": 0.1, "birkhoff6_kahan_li": 0.2, "birkhoff8_kahan_li": 0.4,
}
ORDERS = {"birkhoff2": 2, "birkhoff4": 4, "birkhoff_gauss4": 4, "birkhoff_gauss6": 6, "birkhoff_gauss8": 8,
          "birkhoff4_suzuki": 4, "birkhoff6_kahan_li": 6, "birkhoff8_kahan_li": 8}


def test_the_members_are_the_registrys_birkhoffian_ones():
    registry = [row["name"] for row in simulator.integrators() if row["kind"] in ("Birkhoffian collocation",
                                                                                  "composition")]
    assert list(simulator.BIRKHOFFIAN_MEMBERS) == registry
    assert set(ORDERS) == set(registry)


@pytest.mark.parametrize("member", sorted(ORDERS))
def test_every_member_has_its_order_on_the_pendulum(member, pendulum_reference):
    h = ORDER_STEPS[member]
    errors = []
    for step in (h, h / 2):
        run = simulator.integrate(pendulum(), PENDULUM_START, (0.0, PENDULUM_END), member, step_size=step)
        assert run.success and run.t[-1] == PENDULUM_END and len(run.t) == round(PENDULUM_END / step) + 1
        errors.append(np.max(np.abs(run.y[:, -1] - pendulum_reference)))
    order = math.log2(errors[0] / errors[1])
    print(f"[ measured ] {member}: error {errors[0]:.2e} at h = {h} s, {errors[1]:.2e} at h/2: order {order:.2f}")
    assert abs(order - ORDERS[member]) < 0.35


@pytest.mark.parametrize("member", ["birkhoff2", "birkhoff_gauss8", "birkhoff6_kahan_li"])
def test_the_pendulums_energy_stays_bounded_over_a_long_run(member):
    # Symplectic and symmetric: the energy error oscillates, it does not drift (GNI §IX.8).
    run = simulator.integrate(pendulum(), PENDULUM_START, (0.0, 2000.0), member, step_size=0.1)
    drift = np.abs(pendulum_energy(run.y) - pendulum_energy(PENDULUM_START))
    first, last = drift[: len(drift) // 10].max(), drift[-len(drift) // 10:].max()
    print(f"[ measured ] {member} at h = 0.1 s over 2000 s: |ΔH| first tenth {first:.2e}, last tenth {last:.2e}")
    assert last < 3.0 * first + 1e-14


CONTROLLED = [(member, "adaptive") for member in ("birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8")] + \
    [(member, "reversible") for member in sorted(ORDERS)]


@pytest.mark.parametrize("member, control", CONTROLLED)
def test_both_controls_meet_the_tolerance_on_the_pendulum(member, control, pendulum_reference):
    results = {}
    for tolerance in (1e-6, 1e-9):
        run = simulator.integrate(pendulum(), PENDULUM_START, (0.0, PENDULUM_END), member, step_control=control,
                                  tolerance=tolerance)
        assert run.success, run.message
        assert run.t[0] == 0.0 and run.t[-1] == PENDULUM_END and np.all(np.diff(run.t) > 0)
        results[tolerance] = (np.max(np.abs(run.y[:, -1] - pendulum_reference)), run.nfev, run.nsteps)
    print(f"[ measured ] {member} {control}: " + ", ".join(
        f"tol {tol:.0e}: error {e:.2e}, {n} rhs, {s} steps" for tol, (e, n, s) in results.items()))
    for tolerance, (error, _, _) in results.items():
        assert error <= 2.0 * tolerance
    assert results[1e-9][1] > results[1e-6][1], "a tighter tolerance costs more evaluations"


@pytest.mark.parametrize("form", ["own chart", "identity chart"])
@pytest.mark.parametrize("member", ["birkhoff_gauss4", "birkhoff_gauss6"])
def test_the_damped_oscillator_has_its_order_against_the_closed_form(member, form):
    system = damped_oscillator_in_its_chart() if form == "own chart" else damped_oscillator_in_z()
    exact = damped_oscillator_exact(10.0)
    errors = []
    for h in (0.2, 0.1):
        run = simulator.integrate(system, (1.0, 0.0), (0.0, 10.0), member, step_size=h)
        errors.append(np.max(np.abs(run.y[:, -1] - exact)))
    order = math.log2(errors[0] / errors[1])
    print(f"[ measured ] damped oscillator, {form}, {member}: errors {errors[0]:.2e}, {errors[1]:.2e}: order {order:.2f}")
    assert abs(order - ORDERS[member]) < 0.35


@pytest.mark.parametrize("member", sorted(ORDERS))
def test_the_damped_oscillators_invariant_holds_best_in_its_own_chart(member):
    # I = e^{γt}(p² + γqp + kq²) is constant along q'' + γq' + kq = 0; in the chart w = (q, e^{γt}p)
    # the member steps a Hamiltonian system and keeps I far better than stepping z with K(t) = e^{γt}K₀.
    drifts = {}
    for form, system in (("own chart", damped_oscillator_in_its_chart()), ("identity chart", damped_oscillator_in_z())):
        run = simulator.integrate(system, (1.0, 0.0), (0.0, 50.0), member, step_size=0.1)
        q, p = run.y
        invariant = np.exp(GAMMA * run.t) * (p * p + GAMMA * q * p + STIFFNESS * q * q)
        drifts[form] = np.max(np.abs(invariant / invariant[0] - 1.0))
    print(f"[ measured ] {member}, h = 0.1 s over 50 s: invariant off by {drifts['own chart']:.1e} in its chart, "
          f"{drifts['identity chart']:.1e} in z")
    assert drifts["own chart"] <= drifts["identity chart"] / 2.0


def test_the_adaptive_control_follows_the_damped_oscillator_in_its_chart():
    run = simulator.integrate(damped_oscillator_in_its_chart(), (1.0, 0.0), (0.0, 10.0), "birkhoff_gauss8",
                              step_control="adaptive", tolerance=1e-8)
    error = np.max(np.abs(run.y[:, -1] - damped_oscillator_exact(10.0)))
    print(f"[ measured ] damped oscillator, own chart, gauss8 adaptive at 1e-8: error {error:.2e}, {run.nfev} rhs")
    assert run.success and error <= 2e-8


def python_sleigh(mass=2.0, inertia_at_centre=0.5, centre_offset=0.3):
    """examples/chaplygin_sleigh.h (S.1)-(S.2) with γ = 0, written in Python: z = (π1, θ, m v, J ω),
    K = K₀, B = p1²/2m + p2²/2J, Λ = (-(m a ω², -m a v ω), 0, 0)."""
    inertia = inertia_at_centre + mass * centre_offset ** 2

    def gradient(z, t):
        return (0.0, 0.0, z[2] / mass, z[3] / inertia)

    def force(z, t):
        v, omega = z[2] / mass, z[3] / inertia
        return (-mass * centre_offset * omega ** 2, mass * centre_offset * v * omega, 0.0, 0.0)

    return simulator.BirkhoffianSystem(4, birkhoffian_gradient=gradient, non_birkhoffian_force=force)


SLEIGH_START = np.array([0.0, 0.3, 2.0 * -0.4, (0.5 + 2.0 * 0.09) * 2.0])  # backing up at 0.4 m/s, turning at 2 rad/s


def test_the_sleigh_in_python_is_the_sleigh_in_cpp_at_fixed_steps():
    in_python = simulator.integrate(python_sleigh(), SLEIGH_START, (0.0, 4.0), "birkhoff_gauss8", step_size=0.05)
    in_cpp = simulator.integrate(simulator.ChaplyginSleigh(), SLEIGH_START, (0.0, 4.0), "birkhoff_gauss8",
                                 step_size=0.05)
    difference = np.max(np.abs(in_python.y - in_cpp.y))
    print(f"[ measured ] sleigh at h = 0.05 s: Python vs C++ differ by at most {difference:.1e} over 4 s; rhs "
          f"{in_python.nfev} vs {in_cpp.nfev}")
    assert in_python.success and in_cpp.success and in_python.nsteps == in_cpp.nsteps == 80
    assert difference < 1e-13


@pytest.mark.parametrize("control", ["adaptive", "reversible"])
def test_the_sleigh_in_python_meets_the_tolerance_as_the_sleigh_in_cpp(control):
    # Not step for step: the C++ sleigh also carries the contact point (x, y) as passive coordinates,
    # which its estimate weighs, and takes π1 and θ out of the stage solve's stop rule (kCyclicMask).
    reference = simulator.integrate(simulator.ChaplyginSleigh(), SLEIGH_START, (0.0, 4.0), "birkhoff_gauss8",
                                    step_size=0.005).y[:, -1]
    tolerance = 1e-8
    errors = {}
    for name, system in (("Python", python_sleigh()), ("C++", simulator.ChaplyginSleigh())):
        run = simulator.integrate(system, SLEIGH_START, (0.0, 4.0), "birkhoff_gauss8", step_control=control,
                                  tolerance=tolerance)
        assert run.success, run.message
        errors[name] = (np.max(np.abs(run.y[:, -1] - reference)), run.nsteps)
    print(f"[ measured ] sleigh {control} at {tolerance:.0e}: " +
          ", ".join(f"{name} error {e:.1e} in {n} steps" for name, (e, n) in errors.items()))
    assert all(error <= 2.0 * tolerance for error, _ in errors.values())


def test_a_jacobian_of_ones_own_gives_the_same_run_and_is_counted():
    jacobian = lambda z, t: np.array([[0.0, 1.0], [-math.cos(z[0]), 0.0]])
    given = simulator.integrate(pendulum(jacobian=jacobian), PENDULUM_START, (0.0, 6.0), "birkhoff_gauss6",
                                step_size=0.1)
    differenced = simulator.integrate(pendulum(), PENDULUM_START, (0.0, 6.0), "birkhoff_gauss6", step_size=0.1)
    assert given.njev > 0 and differenced.njev > 0
    assert np.max(np.abs(given.y[:, -1] - differenced.y[:, -1])) < 1e-13
    # central differences evaluate the rates 2·dimension times per Jacobian; the user's does not
    assert differenced.nfev - given.nfev >= 0


# --- bad requests, refused by name ------------------------------------------------------------------

@pytest.mark.parametrize("make, words", [
    (lambda: simulator.BirkhoffianSystem(3, birkhoffian_gradient=lambda z, t: z), "dimension must be 2 or 4"),
    (lambda: simulator.BirkhoffianSystem(2), "birkhoffian_gradient is required"),
    (lambda: simulator.BirkhoffianSystem(2, birkhoffian_gradient=3.0), "birkhoffian_gradient must be a callable"),
    (lambda: simulator.BirkhoffianSystem(2, birkhoffian_gradient=lambda z, t: z, darboux_chart=(abs, abs)),
     "darboux_chart must be"),
])
def test_a_system_that_cannot_be_built_is_refused_by_name(make, words):
    with pytest.raises((TypeError, ValueError), match=words):
        make()


@pytest.mark.parametrize("kwargs, words", [
    ({"integrator": "rk4", "step_size": 0.1}, "not a Birkhoffian member"),
    ({"integrator": "no_such_member", "step_size": 0.1}, "take one of: birkhoff2"),
    ({"step_size": 0.0}, "step_size must be finite and > 0"),
    ({"step_size": float("nan")}, "step_size must be finite and > 0"),
    ({}, "needs step_size"),
    ({"step_size": 0.1, "tolerance": 1e-6}, "tolerance is for step_control"),
    ({"step_control": "adaptive"}, "needs a tolerance"),
    ({"step_control": "adaptive", "tolerance": -1.0}, "finite tolerance > 0"),
    ({"step_control": "sometimes", "tolerance": 1e-6}, "step_control must be"),
    ({"integrator": "birkhoff2", "step_control": "adaptive", "tolerance": 1e-6}, "not for 'birkhoff2'"),
    ({"integrator": "birkhoff4", "step_control": "adaptive", "tolerance": 1e-6}, "not for 'birkhoff4'"),
    ({"step_size": 1e-9, "max_steps": 1000}, "beyond max_steps"),
    ({"step_size": 1e-9, "max_steps": 10 ** 12}, "max_steps must be 1 ... MAX_RECORDED_STATES"),
    ({"step_size": 0.1, "max_steps": 0}, "max_steps must be 1 ... MAX_RECORDED_STATES"),
])
def test_a_request_that_cannot_be_run_is_refused_by_name(kwargs, words):
    with pytest.raises(ValueError, match=words):
        simulator.integrate(pendulum(), PENDULUM_START, (0.0, 1.0), **kwargs)


def test_the_reversible_control_needs_the_identity_chart():
    with pytest.raises(ValueError, match="identity chart"):
        simulator.integrate(damped_oscillator_in_its_chart(), (1.0, 0.0), (0.0, 1.0), step_control="reversible",
                            tolerance=1e-6)


@pytest.mark.parametrize("z0, t_span, words", [
    ((1.0, 0.0, 0.0), (0.0, 1.0), "z0 must hold 2 numbers"),
    ((float("nan"), 0.0), (0.0, 1.0), "not finite"),
    ((1.0, 0.0), (1.0, 0.0), "finite t0 < t1"),
])
def test_bad_starts_and_spans_are_refused_by_name(z0, t_span, words):
    with pytest.raises(ValueError, match=words):
        simulator.integrate(pendulum(), z0, t_span, step_size=0.1)


def test_a_callable_of_the_wrong_shape_is_named():
    system = simulator.BirkhoffianSystem(2, birkhoffian_gradient=lambda z, t: (1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match="birkhoffian_gradient must return a sequence of 2 numbers"):
        simulator.integrate(system, (1.0, 0.0), (0.0, 1.0), step_size=0.1)


def test_an_exception_in_a_callable_reaches_the_caller_as_itself():
    class Mine(Exception):
        pass

    def gradient(z, t):
        if t > 0.5:
            raise Mine("from the user's gradient")
        return (math.sin(z[0]), z[1])

    with pytest.raises(Mine, match="from the user's gradient"):
        simulator.integrate(simulator.BirkhoffianSystem(2, birkhoffian_gradient=gradient), (1.0, 0.0), (0.0, 1.0),
                            step_size=0.1)


def test_a_step_that_fails_for_good_keeps_the_states_before_it():
    # q' = q² (a force Λ = (0, q²): K₀ ż = (−p', q') = Λ) blows up at t = 1/q0 = 1 s: the adaptive
    # control's steps shrink to round-off there.
    blow_up = simulator.BirkhoffianSystem(2, birkhoffian_gradient=lambda z, t: (0.0, 0.0),
                                          non_birkhoffian_force=lambda z, t: (0.0, z[0] ** 2))
    run = simulator.integrate(blow_up, (1.0, 0.0), (0.0, 2.0), "birkhoff_gauss4", step_control="adaptive",
                              tolerance=1e-8)
    print(f"[ measured ] q' = q² from 1: {run.message}; last point t = {run.t[-1]:.6f} s, q = {run.y[0, -1]:.3e}")
    assert run.status == -1 and not run.success
    assert 0.9 < run.t[-1] < 1.0 and len(run.t) > 10


# --- events ---------------------------------------------------------------------------------------

def pendulum_quarter_period(q0):
    """T/4 = K(sin(q0/2)) for q'' = -sin q from rest at q0: the complete elliptic integral of the first
    kind by the arithmetic-geometric mean, K(k) = π / (2 AGM(1, √(1 - k²)))."""
    a, b = 1.0, math.sqrt(1.0 - math.sin(q0 / 2) ** 2)
    for _ in range(10):
        a, b = (a + b) / 2, math.sqrt(a * b)
    return math.pi / (2 * a)


def falling_through_zero(terminal):
    def q(t, z):
        return z[0]
    q.direction = -1
    q.terminal = terminal
    return q


@pytest.mark.parametrize("options", [{"step_size": 0.1}, {"step_control": "adaptive", "tolerance": 1e-12},
                                     {"step_control": "reversible", "tolerance": 1e-12}])
def test_a_terminal_event_ends_the_pendulum_at_its_quarter_period(options):
    exact = pendulum_quarter_period(PENDULUM_START[0])
    run = simulator.integrate(pendulum(), PENDULUM_START, (0.0, PENDULUM_END), "birkhoff_gauss8",
                              events=falling_through_zero(True), **options)
    located = run.t_events[0]
    print(f"[ measured ] pendulum q = 0 ({options}): located at {located[0]:.15f} s, exact {exact:.15f} s, "
          f"off by {abs(located[0] - exact):.1e} s; q there {run.y_events[0][0, 0]:.1e}")
    assert run.status == 1 and run.success and "terminal event 0" in run.message
    assert len(located) == 1 and abs(located[0] - exact) <= 1e-10
    assert run.t[-1] == located[0] and np.array_equal(run.y[:, -1], run.y_events[0][0])
    assert abs(run.y_events[0][0, 0]) < 1e-12


def test_events_that_do_not_end_the_run_find_every_crossing_in_their_direction():
    omega = math.sqrt(STIFFNESS - GAMMA ** 2 / 4)
    phase = math.atan2(GAMMA / 2 / omega, 1.0)  # q ∝ cos(ωt − φ) e^{−γt/2}
    zeros = [(phase + math.pi / 2 + k * math.pi) / omega for k in range(4) if (phase + math.pi / 2 + k * math.pi) / omega < 10]
    def q(t, z):
        return z[0]
    def rising(t, z):
        return z[0]
    rising.direction = 1
    run = simulator.integrate(damped_oscillator_in_its_chart(), (1.0, 0.0), (0.0, 10.0), "birkhoff_gauss8",
                              step_size=0.05, events=[q, rising])
    print(f"[ measured ] damped oscillator q = 0: located {run.t_events[0]}, exact {np.array(zeros)}, worst "
          f"{np.max(np.abs(run.t_events[0] - zeros)):.1e} s")
    assert run.status == 0 and run.t[-1] == 10.0
    assert len(zeros) == 3 and np.max(np.abs(run.t_events[0] - zeros)) <= 1e-10
    assert np.array_equal(run.t_events[1], run.t_events[0][1::2]), "the rising crossings are every second one"
    assert run.y_events[0].shape == (3, 2)


@pytest.mark.parametrize("events, words", [
    ([3.0], "events\\[0\\] must be a callable"),
    (lambda t, z: "high", "must return a number"),
])
def test_bad_events_are_refused_by_name(events, words):
    with pytest.raises(TypeError, match=words):
        simulator.integrate(pendulum(), PENDULUM_START, (0.0, 1.0), step_size=0.1, events=events)


def test_an_event_that_returns_nan_is_refused_by_name():
    with pytest.raises(ValueError, match="event function returned NaN"):
        simulator.integrate(pendulum(), PENDULUM_START, (0.0, 1.0), step_size=0.1, events=lambda t, z: float("nan"))


def test_threads_integrating_their_own_systems_get_the_one_thread_result():
    # integrate() holds the GIL, which the interpreter hands between threads inside the callbacks: four
    # runs interleave at every evaluation. In a child with a timeout (test_simulator_hostile.run_child),
    # so that a hang fails instead of hanging the suite.
    from test_simulator_hostile import run_child
    out = run_child("""
        import math, threading
        import numpy as np
        from birkhoff_cart import simulator
        def pendulum():
            return simulator.BirkhoffianSystem(2, birkhoffian_gradient=lambda z, t: (math.sin(z[0]), z[1]))
        def run():
            return simulator.integrate(pendulum(), (2.0, 0.0), (0.0, 20.0), "birkhoff_gauss8", step_control="adaptive",
                                       tolerance=1e-10)
        expected = run()
        results = [None] * 4
        def work(k):
            results[k] = run()
        for attempt in range(5):
            threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join()
            assert all(np.array_equal(result.y, expected.y) for result in results)
        print("same", expected.nfev)
    """)
    assert out.startswith("same")

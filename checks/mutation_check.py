#!/usr/bin/python3
"""Mutation check: applies a fixed list of named source mutations, one at a time, to a scratch copy
of the repository, builds only the test targets that should notice, runs those tests, and fails
(exit status 1) if any mutation survives — i.e. if every one of its tests still passes.

Usage: /usr/bin/python3 checks/mutation_check.py [--scratch DIR] [--only NAME ...] [--list] [--check-targets]
                                                 [--rotate K] [--junit FILE]

--rotate K applies K mutations chosen from the list by the commit being tested (its hash picks where
in the list they start): each commit checks a different slice, the same commit always the same one,
and the run names the --only command that repeats it. scripts/run_tests.sh runs `--rotate 2
--junit ...` (each mutation a test case: killed passes); the whole list is the command without options.

The working tree is never modified: the tracked files are copied (git ls-files) to
DIR/src/birkhoff_cart (default: $TMPDIR/birkhoff_cart_mutation), configured once with CMake
(catkin, tests on) in DIR/build, and each mutation is applied to the scratch copy and undone before
the next. An unmutated baseline of the same tests must pass first, otherwise the check is
meaningless and it stops. A mutation whose target text is not found exactly once is an error (the
code moved: update the list), not a kill. Repeated runs reuse the scratch build (ccache, make).
"""
import argparse
import hashlib
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parent.parent


class Mutation:
    def __init__(self, name, why, path, original, mutated, tests):
        self.name = name          # short name printed in the report
        self.why = why            # the defect it stands for
        self.path = path          # file, relative to the repository
        self.original = original  # text that must occur exactly once
        self.mutated = mutated    # its replacement
        self.tests = tests        # [(test target, gtest filter)], [("pytest:FILE", -k expression)] or
                                  # [("doc:TARGET", doc block name)]


PYTEST = "pytest:"  # a study-runner test: pytest on the scratch copy's test/python/FILE, selected with -k
DOC = "doc:"        # the doc test: "doc:TARGET" builds TARGET, then runs the doc block named by the -k expression
                    # (test_doc_commands.py against the scratch build's devel space)


TRAJECTORY = "trajectory_vs_independent_model_test"

MUTATIONS = [
    Mutation(
        "nonholonomic_force_sign",
        "the nonholonomic force Λ_nh,1 in ṗ1 = Λ_nh,1 + Q1 enters with the wrong sign",
        "include/birkhoff_cart/core/physics/cart_model.h",
        "rate(0) = nonholonomic_force_at(s, c, quasi_velocity)(0) + generalized_force(0);",
        "rate(0) = -nonholonomic_force_at(s, c, quasi_velocity)(0) + generalized_force(0);",
        [(TRAJECTORY, "*"), ("cart_birkhoffian_test", "*")],
    ),
    Mutation(
        "birkhoff4_weights",
        "birkhoff4 composes birkhoff2 with equal weights 1/3 (birkhoff2's order) instead of the triple jump",
        "include/birkhoff_cart/core/integrators/birkhoff_symplectic.h",
        "const double outer = 1.0 / (2.0 - std::cbrt(2.0));  // γ₁ = γ₃ ≈ 1.3512",
        "const double outer = 1.0 / 3.0;",
        [(TRAJECTORY, "*"), ("registry_properties_test", "*")],
    ),
    Mutation(
        "chart_time_at_step_end",
        "the collocation step leaves the Darboux chart at tₖ instead of tₖ₊₁",
        "include/birkhoff_cart/core/integrators/gauss_collocation.h",
        "z = system.from_darboux(w_next, S(t + h));",
        "z = system.from_darboux(w_next, S(t));",
        [(TRAJECTORY, "*"), ("k_symplectic_test", "*")],
    ),
    Mutation(
        "dropped_air_drag_force",
        "an effect term is dropped: air drag adds its Jacobian but no force",
        "src/core/physics/effects/air_drag.cpp",
        "total.force(0) += -k * std::abs(speed_a) * speed_a * c;",
        "static_cast<void>(c);",
        [(TRAJECTORY, "*"), ("effects_test", "*"), ("independent_model_test", "*")],
    ),
    Mutation(
        "odom_at_hinge",
        "odometry reports the hinge B instead of base_link at the rear-axle midpoint A",
        "src/ros/conversions.cpp",
        "const Eigen::Vector2d rear_axle_midpoint = model.rear_axle_midpoint(state);  // A [m]\n"
        "  const Vector2<double> quasi_velocity(",
        "const Eigen::Vector2d rear_axle_midpoint(state.x, state.y + 0.0 * model.parameters().wheelbase);\n"
        "  const Vector2<double> quasi_velocity(",
        [("conversions_test", "*")],
    ),
    Mutation(
        "nan_drive_torque_accepted",
        "a NaN drive_torque command is accepted",
        "src/core/run/simulation.cpp",
        'require_finite_torque(torque, "drive");',
        "",
        [("bad_input_test", "*"), ("simulation_test", "*")],
    ),
    Mutation(
        "passive_rates_at_first_stage",
        "the passive coordinates (x, y, θ, φ) are integrated with every stage's rate taken at the first stage",
        "include/birkhoff_cart/core/integrators/passive_quadrature.h",
        "system.passive_rates_stages(stage_points, passive_stages, stage_times, passive_rates);",
        "system.passive_rates_stages(stage_points, passive_stages, stage_times, passive_rates);\n"
        "          for (int j = 1; j < Stages; ++j) passive_rates[j] = passive_rates[0];",
        [(TRAJECTORY, "*"), ("integrator_contract_test", "*")],
    ),
    Mutation(
        "gauss_tableau_rows",
        "a Gauss–Legendre coefficient aᵢⱼ integrates the basis up to the wrong node (rows swapped)",
        "src/core/integrators/gauss_legendre_tableau.cpp",
        "tableau.coefficients[i][j] = static_cast<double>(integrate_basis(nodes, s, j, 0.0L, nodes[i]));",
        "tableau.coefficients[i][j] = static_cast<double>(integrate_basis(nodes, s, j, 0.0L, nodes[s - 1 - i]));",
        [(TRAJECTORY, "*"), ("integrator_contract_test", "*"), ("k_symplectic_test", "*")],
    ),
    Mutation(
        "compensated_summation_dropped",
        "the compensated (TwoSum) state update silently falls back to plain summation",
        "include/birkhoff_cart/core/integrators/gauss_collocation.h",
        "const bool compensate = settings_.compensated && system_traits::kDarbouxChartIsLinear<System>;\n"
        "    if (!compensate) {",
        "const bool compensate = false && settings_.compensated && system_traits::kDarbouxChartIsLinear<System>;\n"
        "    if (!compensate) {",
        [("gauss_collocation_test", "*")],
    ),
    Mutation(
        "angle_reduction_turns",
        "the angle reduction loses the whole turns it removes",
        "include/birkhoff_cart/core/integrators/angle_reduction.h",
        "  remainder -= k * kTwoPiLow;\n  turns += k;",
        "  remainder -= k * kTwoPiLow;\n  turns += 0.0 * k;",
        [("gauss_collocation_test", "*"), ("long_run_test", "*")],
    ),
    Mutation(
        "time_transform_passive_rates",
        "the time transformation scales ż by 1/σ but not the passive rates ẏ (positions advance in fictive time)",
        "include/birkhoff_cart/core/integrators/time_transformed_system.h",
        "rate.template head<System::kPassiveDimension>() = rates * inverse_density;",
        "rate.template head<System::kPassiveDimension>() = rates * S(1.0);",
        [("reversible_step_control_test", "*")],
    ),
    Mutation(
        "adaptive_accepts_every_step",
        "the error-per-step control accepts a step whatever its estimate says",
        "include/birkhoff_cart/core/integrators/adaptive_step_control.h",
        "if (!solved || !finite_point() || !(ratio <= settings_.acceptance_ratio) ||",
        "if (!solved || !finite_point() || !(ratio <= 1e30) ||",
        [("adaptive_step_control_test", "*")],
    ),
    Mutation(
        "compensated_remainder_counted_twice",
        "the compensated update counts the carried remainder once more for each stage weight (odd s)",
        "include/birkhoff_cart/core/integrators/gauss_collocation.h",
        "W increment = S(tableau.remainder_weight) * w_remainder;",
        "W increment = w_remainder;",
        [("gauss_collocation_test", "*")],
    ),
    Mutation(
        "error_estimate_weights",
        "the local error estimate's end-point weight has the wrong sign",
        "src/core/integrators/gauss_legendre_tableau.cpp",
        "tableau.estimate_weights[s + 1] = static_cast<double>(-end_sign * beta);",
        "tableau.estimate_weights[s + 1] = static_cast<double>(end_sign * beta);",
        [("error_estimate_test", "*")],
    ),
    Mutation(
        "accuracy_guard_comparison",
        "the accuracy guard compares with the warning limit where the error limit belongs",
        "src/core/scene/accuracy_guard.cpp",
        "if (value > limit.error) note(quantity, AccuracyLevel::kError, limit.error);",
        "if (value > limit.warn) note(quantity, AccuracyLevel::kError, limit.error);",
        [("accuracy_guard_test", "*")],
    ),
    Mutation(
        "effect_coefficient_range",
        "the effect table lets rolling resistance's speed_epsilon be 0 (tanh(v/0): NaN forces from rest)",
        "src/core/physics/effects/effect_library.cpp",
        '{"speed_epsilon", Range::kPositive, "m/s", 0.05, 0.01, 0.2}',
        '{"speed_epsilon", Range::kNonNegative, "m/s", 0.05, 0.01, 0.2}',
        [("scene_test", "*")],
    ),
    Mutation(
        "sleigh_blade_reaction_sign",
        "the example system's blade reaction turns the sleigh the wrong way (J ω̇ = +m a v ω)",
        "include/birkhoff_cart/core/examples/chaplygin_sleigh.h",
        "return Eigen::Matrix<S, 2, 1>(m * a * (p2 / j) * (p2 / j), -a * (p1 / j) * p2);",
        "return Eigen::Matrix<S, 2, 1>(m * a * (p2 / j) * (p2 / j), a * (p1 / j) * p2);",
        [("chaplygin_sleigh_test", "*"), ("integrator_contract_test", "*Sleigh*")],
    ),
    Mutation(
        "cmd_vel_timeout_ignored",
        "cmd_vel_controller never notices that cmd_vel fell silent (the cart keeps driving)",
        "src/core/node_logic/cmd_vel_controller.cpp",
        "const bool silent = has_command_ && s.cmd_vel_timeout > 0.0 && feedback.time - command_time_ > s.cmd_vel_timeout;",
        "const bool silent = has_command_ && s.cmd_vel_timeout < 0.0 && feedback.time - command_time_ > s.cmd_vel_timeout;",
        [("cmd_vel_controller_test", "*")],
    ),
    Mutation(
        "restart_speed_unchecked",
        "a teleport's forward speed is not checked against what one step resolves (1e200 m/s accepted)",
        "src/core/physics/restart_state.cpp",
        "require_within(\"forward_speed\", s.forward_speed, kLargestStepFraction * wheelbase / step_size, \"m/s\",",
        "require_within(\"forward_speed\", s.forward_speed, 1e300 * wheelbase / step_size, \"m/s\",",
        [("restart_test", "*")],
    ),
    Mutation(
        "restart_without_trial_step",
        "a teleport is committed without its trial step (a state whose first step fails is accepted)",
        "src/core/run/simulation.cpp",
        "  check_trial_step(restarted);\n",
        "",
        [("restart_test", "*")],
    ),
    Mutation(
        "follower_replays_the_leaders_past",
        "a follower's run starts at its scene's t0 however far the leader's clock is ahead",
        "src/core/node_logic/run_timeline.cpp",
        "if (!(leader_time - scene_start > longest_catch_up)) return scene_start;",
        "if (!(leader_time - scene_start > longest_catch_up) || true) return scene_start;",
        [("run_timeline_test", "*")],
    ),
    Mutation(
        "bag_index_chunk_count",
        "the bag's file header counts one chunk fewer than it holds",
        "src/ros/bag_file_writer.cpp",
        'append_value_field(out, "chunk_count", static_cast<std::uint32_t>(chunks_.size()));',
        'append_value_field(out, "chunk_count", static_cast<std::uint32_t>(chunks_.size() - 1));',
        [("bag_file_writer_test", "*")],
    ),
    Mutation(
        "reference_judges_unresolved_goal",
        "a study's reference judges goals it does not resolve (its check disagrees by more than a tenth of them)",
        "src/birkhoff_cart_study/references.py",
        "if RESOLUTION * spread > goal:",
        "if RESOLUTION * spread > goal * 1e30:",
        [(PYTEST + "test_study_outcomes.py", "resolves_a_goal or unresolved_reference")],
    ),
    Mutation(
        "cli_csv_fixed_columns",
        "the CLI contract's CSV check expects 14 or 15 columns instead of the header's own list",
        "src/birkhoff_cart_study/cli_contract.py",
        "if len(fields) != len(header):",
        "if len(fields) not in (14, 15):",
        [(PYTEST + "test_study_outcomes.py", "own_columns")],
    ),
    Mutation(
        "richardson_shadow_follows_each_step",
        "the global error estimate's shadow takes each grid step alone instead of two at once: the same step "
        "map from its own state, so it reads no error",
        "include/birkhoff_cart/core/integrators/richardson_shadow.h",
        "if (!pending_ && !closes) {",
        "if (!pending_ && !closes && false) {",
        [("global_error_estimate_test", "*")],
    ),
    Mutation(
        "side_step_solves_to_round_off",
        "a side step to an output row converges its stage solve to round-off instead of the accuracy the "
        "tolerance needs: the same rows, several more iterations each",
        "src/core/cart_binding/adaptive_cart_stepper.h",
        "side_memory_.start_side_step_from(grid_memory, side_stage_change_per_unit_step_ * (target - start) / pieces,",
        "side_memory_.start_side_step_from(grid_memory, 0.0 * (target - start) / pieces,",
        [("adaptive_step_control_test", "SideSteps.*")],
    ),
    Mutation(
        "cli_ignores_output_rate",
        "cart_simulate accepts --output-rate but ignores it: the documented whirl command (h = 0.02 s, "
        "--output-rate 10) is refused for the scene's 100 Hz output",
        "src/apps/cart_simulate.cpp",
        'if (option == "--output-rate") scene.output_rate = parse_positive(option, text);',
        'if (option == "--output-hz") scene.output_rate = parse_positive(option, text);',
        [(DOC + "cart_simulate", "cli-1-cart_simulate")],
    ),
    Mutation(
        "bag_claim_ignores_lock",
        "a recorder takes another running recorder's locked <path>.active for a killed run's file",
        "src/ros/bag_file_claim.cpp",
        "if (::flock(found.get(), LOCK_EX | LOCK_NB) != 0) {",
        "if (false) {",
        [("bag_file_claim_test", "*")],
    ),
    Mutation(
        "linear_mode_error_unweighted_out",
        "the adaptive control's estimate drops the linearised error (B.55): a ringing stiff mode is stepped over unseen",
        "include/birkhoff_cart/core/integrators/collocation_error_estimate.h",
        "    if (memory.linear_mode_error) {",
        "    if (false) {",
        [("adaptive_step_control_test", "*SteppedOver*"), ("system_step_controls_test", "*Linearised*")],
    ),
    Mutation(
        "passive_coordinates_measured_relatively",
        "ê measures the passive coordinates relatively above 1 SI unit again (accuracy.md (A.1)): the step "
        "errors of the loads' work and the wheel angles grow with them, and the stiff hinge ends beyond twice "
        "its tolerance",
        "include/birkhoff_cart/core/integrators/error_estimate.h",
        "  const double y_norm = absolute_max_norm(y_error);",
        "  const double y_norm = weighted_max_norm(y_start, y_error);",
        [("error_estimate_test", "*PassiveCoordinatesCountAbsolutely*"),
         ("adaptive_step_control_test", "ToleranceProportionality.*")],
    ),
    Mutation(
        "torque_memo_keeps_first_value",
        "a torque profile's memo fills an entry once and never compares the time again: stale torques",
        "include/birkhoff_cart/core/physics/effects/torque_source.h",
        "    if (entry.time_bits != bits) {",
        "    if (entry.time_bits == 0x7FF8000000000000ULL) {",
        [("effects_test", "TorqueSource*")],
    ),
]


def run(command, cwd=None, log=None):
    """Runs `command`; returns (exit status, combined output)."""
    result = subprocess.run(command, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if log is not None:
        log.write(f"$ {' '.join(map(str, command))}\n{result.stdout}\n")
        log.flush()
    return result.returncode, result.stdout


def copy_tracked_files(source_root: pathlib.Path):
    status, listing = run(["git", "-C", str(REPO), "ls-files", "-z"])
    if status != 0:
        sys.exit(f"mutation_check: git ls-files failed in {REPO}")
    source_root.mkdir(parents=True, exist_ok=True)
    for name in listing.split("\0"):
        if not name:
            continue
        source = REPO / name
        target = source_root / name
        if not source.is_file():
            continue
        if target.is_file() and target.read_bytes() == source.read_bytes():
            continue  # unchanged: keep its time stamp so make rebuilds nothing
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target)


def find_binary(build: pathlib.Path, target: str) -> pathlib.Path:
    for candidate in (build / "devel/lib/birkhoff_cart" / target, build / target):
        if candidate.is_file():
            return candidate
    found = [p for p in build.rglob(target) if p.is_file() and os.access(p, os.X_OK)]
    if not found:
        raise FileNotFoundError(f"test binary {target} not found under {build}")
    return found[0]


def require_scratch_library(build: pathlib.Path, binary: pathlib.Path):
    """Exits unless `binary` loads the scratch build's libbirkhoff_cart_core.so. The test binaries
    find it through RUNPATH, which LD_LIBRARY_PATH overrides: under a caller that sourced another
    workspace's devel/setup.bash, a mutation of the library's .cpp files would be tested against
    that workspace's pristine library and survive. main() puts the scratch library first."""
    status, listing = run(["ldd", str(binary)])
    expected = f"libbirkhoff_cart_core.so => {build / 'devel/lib'}/"
    if status != 0 or (expected not in listing and "libbirkhoff_cart_core.so" in listing):
        sys.exit(f"mutation_check: {binary.name} does not load the scratch library ({expected}...):\n{listing}")


def build_and_run(build: pathlib.Path, tests, log):
    """Builds the targets of `tests` and runs each; returns (built, [failing tests], [passing tests])."""
    targets = sorted({target[len(DOC):] if target.startswith(DOC) else target
                      for target, _ in tests if not target.startswith(PYTEST)})
    # A scratch build configured before a test file was added knows no target for it: re-glob first.
    status, output = run(["make", "-C", str(build), "cmake_check_build_system"], log=log) if targets else (0, "")
    if status == 0 and targets:
        status, output = run(["make", "-C", str(build), "-j2", *targets], log=log)
    if status != 0:
        return False, [], []
    failing, passing = [], []
    for target, gtest_filter in tests:
        if target.startswith(PYTEST):
            test_file = build.parent / "src/birkhoff_cart/test/python" / target[len(PYTEST):]
            status, output = run(["/usr/bin/python3", "-m", "pytest", "-q", "-p", "no:cacheprovider", str(test_file),
                                  "-k", gtest_filter], log=log)
            (failing if status != 0 else passing).append(f"{target} -k '{gtest_filter}'")
            continue
        if target.startswith(DOC):
            test_file = build.parent / "src/birkhoff_cart/test/python/test_doc_commands.py"
            status, output = run(["env", f"BIRKHOFF_CART_DEVEL={build / 'devel'}", "/usr/bin/python3", "-m", "pytest",
                                  "-q", "-p", "no:cacheprovider", str(test_file), "-k", gtest_filter], log=log)
            (failing if status != 0 else passing).append(f"doc block {gtest_filter}")
            continue
        binary = find_binary(build, target)
        require_scratch_library(build, binary)
        status, output = run([str(binary), f"--gtest_filter={gtest_filter}"], log=log)
        label = f"{target} --gtest_filter={gtest_filter}"
        (failing if status != 0 else passing).append(label)
    return True, failing, passing


def check_targets(mutations, root=REPO) -> int:
    """Exit status 0 when every mutation can still be applied: its target text occurs exactly once
    and the mutated text differs from it; otherwise 1, naming each stale mutation."""
    stale = []
    for mutation in mutations:
        path = root / mutation.path
        count = path.read_text().count(mutation.original) if path.is_file() else -1
        if count != 1 or mutation.mutated == mutation.original:
            where = "file missing" if count < 0 else f"target found {count} times"
            stale.append(f"{mutation.name}: {where} in {mutation.path}")
    for line in stale:
        print(f"mutation_check: STALE {line}: update the mutation where the code moved")
    print(f"mutation_check: {len(mutations) - len(stale)} of {len(mutations)} mutation targets apply")
    return 1 if stale else 0


def rotation(mutations, count, root=REPO):
    """`count` consecutive mutations (cyclically) starting where HEAD's commit hash points."""
    status, head = run(["git", "-C", str(root), "rev-parse", "HEAD"])
    key = head.strip() if status == 0 else "no-commit"
    start = int(hashlib.sha256(key.encode()).hexdigest(), 16) % len(mutations)
    count = min(count, len(mutations))
    return [mutations[(start + i) % len(mutations)] for i in range(count)], key[:12]


def write_junit(path: pathlib.Path, cases):
    """cases: [(name, seconds, failure text or None)] as one JUnit test suite."""
    from xml.sax.saxutils import escape, quoteattr
    failures = sum(1 for _, _, failure in cases if failure)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<testsuite name="mutation_check" tests="{len(cases)}" failures="{failures}" errors="0">']
    for name, seconds, failure in cases:
        lines.append(f'  <testcase classname="mutation_check" name={quoteattr(name)} time="{seconds:.0f}">')
        if failure:
            lines.append(f'    <failure message={quoteattr(failure)}>{escape(failure)}</failure>')
        lines.append("  </testcase>")
    lines.append("</testsuite>")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scratch", type=pathlib.Path,
                        default=pathlib.Path(tempfile.gettempdir()) / "birkhoff_cart_mutation")
    parser.add_argument("--only", nargs="*", help="names of the mutations to apply (default: all)")
    parser.add_argument("--list", action="store_true", help="list the mutations and exit")
    parser.add_argument("--check-targets", action="store_true",
                        help="only check, in seconds and without building, that every mutation's target text "
                             "occurs exactly once in the working tree (CI runs this on every change)")
    parser.add_argument("--root", type=pathlib.Path, default=REPO,
                        help="with --check-targets: the source tree to check (default: this repository)")
    parser.add_argument("--rotate", type=int, metavar="K",
                        help="apply K mutations chosen by the commit hash instead of the whole list")
    parser.add_argument("--junit", type=pathlib.Path, metavar="FILE",
                        help="also write each mutation as a JUnit test case (killed = passed)")
    arguments = parser.parse_args()
    if arguments.rotate is not None and (arguments.rotate < 1 or arguments.only):
        parser.error("--rotate takes a positive count and excludes --only")
    if arguments.list:
        for mutation in MUTATIONS:
            tests = ", ".join(target for target, _ in mutation.tests)
            print(f"{mutation.name}: {mutation.why} ({mutation.path}; killed by {tests})")
        return 0
    if arguments.check_targets:
        return check_targets(MUTATIONS, arguments.root.resolve())
    chosen = [m for m in MUTATIONS if not arguments.only or m.name in arguments.only]
    unknown = set(arguments.only or []) - {m.name for m in MUTATIONS}
    if unknown:
        sys.exit(f"mutation_check: unknown mutation(s) {', '.join(sorted(unknown))}; --list shows them")
    if arguments.rotate is not None:
        chosen, commit = rotation(MUTATIONS, arguments.rotate)
        names = " ".join(m.name for m in chosen)
        print(f"mutation_check: {len(chosen)} of {len(MUTATIONS)} mutations for commit {commit}; "
              f"repeat with --only {names}", flush=True)
    cases = []  # for --junit

    started = time.time()
    scratch = arguments.scratch.resolve()
    source = scratch / "src/birkhoff_cart"
    build = scratch / "build"
    scratch.mkdir(parents=True, exist_ok=True)
    log = open(scratch / "mutation_check.log", "w")
    print(f"mutation_check: scratch copy in {scratch} (log: {scratch / 'mutation_check.log'})", flush=True)
    copy_tracked_files(source)

    environment_path = "/usr/bin:/bin:" + os.environ.get("PATH", "")
    os.environ["PATH"] = environment_path
    os.environ.setdefault("CCACHE_BASEDIR", str(scratch))
    library_path = os.environ.get("LD_LIBRARY_PATH")
    os.environ["LD_LIBRARY_PATH"] = str(build / "devel/lib") + (":" + library_path if library_path else "")
    if not (build / "Makefile").is_file():
        build.mkdir(parents=True, exist_ok=True)
        launcher = ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"] if shutil.which("ccache") else []
        status, output = run(["cmake", "-S", str(source), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                              "-DCATKIN_ENABLE_TESTING=ON", "-DPYTHON_EXECUTABLE=/usr/bin/python3",
                              "-DPython3_EXECUTABLE=/usr/bin/python3", *launcher], log=log)
        if status != 0:
            print(output[-3000:])
            sys.exit("mutation_check: CMake configuration of the scratch copy failed")

    # Baseline: the unmutated tests must pass, or a "kill" would mean nothing.
    all_tests = sorted({test for mutation in chosen for test in mutation.tests})
    built, failing, _ = build_and_run(build, all_tests, log)
    if not built or failing:
        why = "the UNMUTATED baseline does not pass: " + (", ".join(failing) or "build failed")
        print("mutation_check: " + why)
        if arguments.junit:
            write_junit(arguments.junit, [("baseline", time.time() - started, why + f" (log {log.name})")])
        return 1
    print(f"baseline: {len(all_tests)} test runs pass ({time.time() - started:.0f} s)", flush=True)

    killed, survived, broken = [], [], []
    for mutation in chosen:
        path = source / mutation.path
        pristine = (REPO / mutation.path).read_text()
        occurrences = pristine.count(mutation.original)
        if occurrences != 1:
            broken.append(mutation.name)
            print(f"ERROR    {mutation.name}: its target text occurs {occurrences} times in {mutation.path}")
            cases.append((mutation.name, 0.0, f"target text occurs {occurrences} times in {mutation.path}"))
            continue
        began = time.time()
        try:
            path.write_text(pristine.replace(mutation.original, mutation.mutated))
            built, failing, passing = build_and_run(build, mutation.tests, log)
        finally:
            path.write_text(pristine)
        seconds = time.time() - began
        if not built:
            broken.append(mutation.name)
            print(f"ERROR    {mutation.name}: the mutated source does not build ({seconds:.0f} s; see the log)")
            cases.append((mutation.name, seconds, f"the mutated source does not build (log {log.name})"))
        elif failing:
            killed.append(mutation.name)
            print(f"killed   {mutation.name} ({mutation.why}) by {'; '.join(failing)} ({seconds:.0f} s)", flush=True)
            cases.append((mutation.name, seconds, None))
        else:
            survived.append(mutation.name)
            print(f"SURVIVED {mutation.name} ({mutation.why}): {'; '.join(passing)} all pass ({seconds:.0f} s)",
                  flush=True)
            cases.append((mutation.name, seconds, f"SURVIVED: {mutation.why}; {'; '.join(passing)} all pass"))
    # The scratch sources are pristine again and newer than the mutated objects: the next run's
    # baseline rebuilds what a mutation touched.
    total = len(chosen)
    if arguments.junit:
        write_junit(arguments.junit, cases)
    print(f"{len(killed)} of {total} mutations killed, {len(survived)} survived, {len(broken)} errors "
          f"({time.time() - started:.0f} s)")
    return 0 if len(killed) == total else 1


if __name__ == "__main__":
    sys.exit(main())

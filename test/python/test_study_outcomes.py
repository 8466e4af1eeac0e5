"""How a task's process is judged and reported: the CLI contract's CSV check reads the scene's own
columns from the header; a refusal's reason is its error line even with the usage text after it;
the registry comes from the JSON listing; a reference judges only the goals it resolves; and no
rows a valid study can produce crash the report."""
import json
import math
import os

import pytest

from birkhoff_cart_study.cli_contract import check_csv, error_line, judge
from birkhoff_cart_study.kinds import work_precision_report
from birkhoff_cart_study.race import race
from birkhoff_cart_study.references import Resolution, distances
from birkhoff_cart_study.registry import parse_listing
from birkhoff_cart_study.report import write_report
from birkhoff_cart_study.study import load_study
from conftest import LISTING, SCENE_DIR
from test_study_schema import CLI_RUNS, RANDOM_CARTS, WORK_PRECISION

BASE = "t,x,y,theta,chi,phi1,phi2,phi3,phi4,pi1,omega1,omega2,energy,p2,local_error_estimate"
ODOMETRY = ",odom_x,odom_y,odom_theta,odom_sigma_position,odom_sigma_theta"


def csv(tmp_path, header, rows):
    path = tmp_path / "out.csv"
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    return str(path)


def row(t, extra=0, estimate=""):
    return ",".join([repr(t)] + ["0.5"] * 13 + [estimate] + ["1.0"] * extra)


def test_the_csv_check_reads_the_scene_s_own_columns(tmp_path):
    # noisy_odometry: 20 columns; the estimate empty for a member without one
    path = csv(tmp_path, BASE + ODOMETRY, [row(0.0, 5), row(0.5, 5, "1e-9"), row(1.0, 5)])
    assert check_csv(path, 0.0, 1.0, 0.5, complete=True) is None
    path = csv(tmp_path, BASE + ODOMETRY + ",steering_torque_applied", [row(0.0, 6), row(1.0, 5)])
    assert check_csv(path, 0.0, 1.0, 0.5, complete=True) == "line 3 has 20 fields, the header 21"
    path = csv(tmp_path, BASE, [row(0.0), "0.5," + ",".join(["x"] * 13) + ","])
    assert check_csv(path, 0.0, None, 0.5, complete=True) == "line 3 does not parse"
    path = csv(tmp_path, BASE, [row(0.0), row(0.0)])
    assert check_csv(path, 0.0, None, 0.5, complete=True) == "row times not strictly increasing"


USAGE = "usage: cart_simulate --scene FILE [--integrator NAME]\n  --scene FILE  scene YAML\ncart_simulate: not this one\n"


def test_the_reason_of_a_refusal_is_its_error_line_not_the_usage():
    stderr = "cart_simulate: option --tolerance is dopri5's local tolerance [-]; rk4 steps at --step H\n" + USAGE
    assert error_line(stderr).startswith("cart_simulate: option --tolerance is dopri5's")
    assert judge(2, stderr, "/nonexistent.csv", None, None, 0.01) == ("refused", "exit 2: --tolerance with a fixed-step member")
    drift = "cart_simulate: warning: the paper form drifts\ncart_simulate: step failed after t = 1 s: singular\n"
    assert error_line(drift) == "cart_simulate: step failed after t = 1 s: singular"
    progress = "cart_simulate:  50.0 % of scene time (t = 1 s of 2 s), real-time factor 3\n"
    assert error_line(progress + "cart_simulate: accuracy ERROR in energy\n") == "cart_simulate: accuracy ERROR in energy"
    assert judge(3, "Segmentation fault\n", "/nonexistent.csv", None, None, 0.01)[0] == "failed"
    assert judge(4, "cart_simulate: unexpected error: boom\n", "/x.csv", None, None, 0.01)[0] == "failed"


def test_the_registry_is_read_from_the_json_listing():
    registry = parse_listing(json.dumps(LISTING))
    assert registry.names[:3] == ["birkhoff2", "birkhoff4", "rk2"]
    assert registry.adaptive == ["dopri5"]
    assert registry.member("birkhoff_gauss8").reversible and not registry.member("rk4").reversible
    assert registry.forms == ("autonomous", "paper")
    for bad in ("", "{}", "[1]", '{"integrators": [], "birkhoffian_forms": ["a"], "step_controls": ["f"]}',
                "usage: cart_simulate --scene FILE"):
        with pytest.raises(ValueError, match="--list-integrators --json"):
            parse_listing(bad)


def reference_text(points):
    return "# reference\nt,x,y,heading,heading_low,arc_length\n" + "".join(
        "%r,%r,%r,0,0,0\n" % (t, x, y) for t, x, y in points)


def test_a_reference_resolves_a_goal_only_to_a_tenth_of_it():
    spreads = distances(reference_text([(10.0, 1.0, 2.0), (30.0, 3.0, 4.0)]),
                        reference_text([(10.0, 1.0, 2.0 + 3e-10), (30.0, 3.0 + 4e-8, 4.0)]))
    assert [t for t, _ in spreads] == [10.0, 30.0]
    resolution = Resolution("whirl", spreads)
    assert resolution.why_unresolved(1e-3, 30.0, "e") is None
    assert "differ by 4e-08 m, more than a tenth of 1e-07 m" in resolution.why_unresolved(1e-7, 30.0, "e")
    assert resolution.why_unresolved(1e-8, 10.0, "e") is None  # up to 10 s the spread is 3e-10 m
    assert "failed" in Resolution("w", failure="failed (exit 1)").why_unresolved(1.0, 1.0, "e")
    assert Resolution("closed form", exact=True).why_unresolved(1e-15, 1.0, "e") is None


def run(method, cpu, error, setting="h=1"):
    return {"method": method, "setting": setting, "cpu": cpu, "error": error, "energy_rel": error,
            "energy": error}


def test_the_race_gives_no_verdict_and_no_ratio_for_an_unresolved_goal():
    goals = [("error", 1e-3, "error ≤ 0.001 m"), ("error", 1e-8, "error ≤ 1e-08 m")]
    runs = [run("birkhoff_gauss8", 1.0, 1e-10), run("rk4", 2.0, 1e-10)]
    table, summary = race(runs, goals, lambda m: m.startswith("birkhoff"), {1: "why"}, error_floor=1e-7)
    rk4 = [line for line in table.splitlines() if line.startswith("| `rk4`")][0]
    assert rk4.split(" | ")[1].startswith("2.00× met (2 s)") and rk4.split(" | ")[2] == "unresolved"
    assert "unresolved: no verdict" in table
    assert "at 1 of 1 goals" in summary and "No verdict for error ≤ 1e-08 m" in summary
    assert "errors below 1e-07 m unresolved" in rk4  # the crossover from resolved errors only
    table, _ = race(runs, goals, lambda m: m.startswith("birkhoff"), {}, error_floor=1e-13)
    assert "unresolved" not in table  # a floor below every error clips nothing


def rows_of(tasks, outcome_of):
    rows = []
    for task in tasks:
        row = dict(task.fields(), task_id=task.id, workers=2, load_average_1min=1.0, process_cpu_s=0.01)
        row.update(outcome_of(task))
        rows.append(row)
    return rows


def test_a_study_with_an_unresolved_reference_says_so_in_the_page(registry, study_file, tmp_path):
    study, tasks = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR)

    def outcome(task):
        if task.kind.value in ("reference", "reference_check"):
            x = 643.0 if task.kind.value == "reference" else 0.0
            return {"outcome": "ok", "result": {"reference": task.kind.value},
                    "reference_text": reference_text([(t, x, 0.0) for t in task.settings["checkpoints"]])}
        return {"outcome": "ok", "result": {"cpu_median_s": 0.01, "wall_median_s": 0.01, "position_error_m": 643.0,
                                            "max_energy_residual_rel": 1e-12, "max_energy_residual_J": 1e-12,
                                            "max_p2_residual": 0.0, "rhs_evaluations": 100, "duration_s": 30.0,
                                            "checkpoints": [[10.0, 1.0, 1e-12], [30.0, 643.0, 1e-12]]}}
    page = str(tmp_path / "report" / "results.md")
    unresolved = write_report(study, rows_of(tasks, outcome), page, "study x", "summary")
    assert len(unresolved) == 3 and all("differ by 6.4e+02 m" in line for line in unresolved)
    text = open(page).read()
    assert "**No verdict for 3 goals" in text and "| `birkhoff_gauss4` | unresolved | unresolved | unresolved |" in text
    assert os.path.exists(str(tmp_path / "report" / "results_whirl_30s.png"))


def weird_outcomes(task):
    """Every outcome a row can have, with what a crash, a timeout or an old runner leaves."""
    choices = [{"outcome": "failed", "reason": "exit 1 | x\nline"}, {"outcome": "timeout"}, {},
               {"outcome": "step_failed", "reason": None}, {"outcome": "ok", "result": None},
               {"outcome": "ok", "result": {"position_error_m": None, "cpu_median_s": None}},
               {"outcome": "refused", "reason": "exit 3: x"}, {"outcome": "ok", "result": {"x": math.nan, "y": 1.0}}]
    return choices[hash(task.id) % len(choices)]


@pytest.mark.parametrize("text", [WORK_PRECISION, CLI_RUNS, RANDOM_CARTS], ids=["work_precision", "cli_runs", "random_carts"])
def test_no_rows_crash_the_report(text, registry, study_file, tmp_path):
    text = text.replace("experiments:", "description: 'quotes \" and | pipes, ünïcödé,\\n two lines'\nexperiments:", 1)
    study, tasks = load_study(study_file(text), registry, SCENE_DIR)
    for rows in ([], rows_of(tasks, weird_outcomes), rows_of(tasks, lambda t: {"outcome": "ok"})):
        page = str(tmp_path / "page.md")
        write_report(study, rows, page, "study x", "summary | line")
        assert open(page).read().startswith("# Results: ")


def test_the_page_names_the_experiments_whose_rows_another_build_measured():
    from birkhoff_cart_study.report import other_builds
    now = [{"label": "a", "build": "`new`"}, {"label": "b", "build": "`new`"}, {"label": "b", "build": "`new`"}]
    assert other_builds(now) == "none"
    assert other_builds(now + [{"label": "c"}]) == \
        "c: an earlier build that recorded none (rows measured with glibc's libm reproduce on their own CPU only)"
    assert other_builds(now + [{"label": "a", "build": "`old`"}]) == "a: `old`"

"""docs/results.md describes the landed build: the work–precision page records the source commit it
was written from, and a fixed sample of its rows (bench/results/work_precision/rows.jsonl, the rows
the page is generated from) measured again with the current build gives the same errors and
evaluation counts, bit for bit (times are not compared). The figures other pages quote from it
(README.md's count of goals met, docs/benchmarks.md's verdicts per goal) are the page's, and
docs/accuracy.md §4.2 quotes the shipped reversible_whirl table. A change that moves them fails here until
the page is regenerated (docs/benchmarks.md: `bash scripts/run_benchmark.sh`, then the page and its
rows are committed with the change).

The sample: one row of every registry member and step control and of each Boost.Odeint peer family,
on the short scenes (paper_special against its closed form; sine_steer_torque, drive_rr_drag and
very_stiff_hinge against their references, which are measured again too and must give the shipped
reference files): about 30 runs of milliseconds each. Each runs as the study runner runs it (the
study's own tasks, wired by its work_precision kind, one process each), with one repetition.

Run by scripts/run_tests.sh (pytest-test_results_sample.xml), or after `source .ws/devel/setup.bash`:
python3 -m pytest test/python/test_results_sample.py."""
import os
import pathlib
import re
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "src"))

from birkhoff_cart_study.engine import latest_rows, read_rows  # noqa: E402
from birkhoff_cart_study.kinds import work_precision  # noqa: E402
from birkhoff_cart_study import report  # noqa: E402
from birkhoff_cart_study.registry import read_registry  # noqa: E402
from birkhoff_cart_study.study import load_study  # noqa: E402

BIN = pathlib.Path(os.environ.get("BIRKHOFF_CART_BIN_DIR", REPO / ".ws" / "devel" / "lib" / "birkhoff_cart"))
PAGE = REPO / "docs" / "results.md"
STUDY = REPO / "bench" / "studies" / "work_precision.yaml"
ROWS = REPO / "bench" / "results" / "work_precision" / "rows.jsonl"

# (experiment label, method, its setting: a step [s] or a tolerance) of the rows measured again.
SAMPLE = [
    ("paper_special", "birkhoff2", 0.0025),
    ("paper_special", "birkhoff_gauss8", 0.005),
    ("paper_special", "rk4", 0.0025),
    ("paper_special", "midpoint", 0.0025),
    ("paper_special", "birkhoff_gauss8_adaptive", 1e-06),
    ("paper_special", "dopri5", 1e-08),
    ("sine_steer_torque", "birkhoff_gauss4", 0.2),
    ("sine_steer_torque", "birkhoff_gauss6", 0.025),
    ("sine_steer_torque", "birkhoff4", 0.025),
    ("sine_steer_torque", "birkhoff4_suzuki", 0.025),
    ("sine_steer_torque", "birkhoff6_kahan_li", 0.1),
    ("sine_steer_torque", "birkhoff8_kahan_li", 0.1),
    ("sine_steer_torque", "rk2", 0.025),
    ("sine_steer_torque", "birkhoff_gauss6_adaptive", 1e-06),
    ("sine_steer_torque", "odeint_rkf78", 1e-08),
    ("sine_steer_torque", "odeint_rk4", 0.025),
    ("drive_rr_drag", "birkhoff_gauss8", 0.025),
    ("drive_rr_drag", "birkhoff2", 0.025),
    ("drive_rr_drag", "birkhoff_gauss4_adaptive", 1e-05),
    ("drive_rr_drag", "dopri5", 1e-10),
    ("drive_rr_drag", "odeint_dopri5", 1e-08),
    ("drive_rr_drag", "odeint_bulirsch_stoer", 1e-08),
    ("drive_rr_drag", "odeint_bulirsch_stoer_dense_out", 1e-08),
    ("very_stiff_hinge", "birkhoff_gauss8_reversible", 0.001),
    ("very_stiff_hinge", "birkhoff_gauss8", 0.005),
]
# glibc's dynamic loader (x86-64), which lists the CPU features glibc uses.
LOADER = "/lib64/ld-linux-x86-64.so.2"
# What a measurement's result holds that depends on the machine and its load, not on the build.
TIMES = {"cpu_median_s", "wall_median_s", "wall_s", "repetitions"}


def page_stage_evaluation():
    match = re.search(r"^\| stage evaluation \| (scalar|vector) \|$", PAGE.read_text(), re.M)
    assert match, "docs/results.md records no stage evaluation: regenerate it (docs/benchmarks.md)"
    return match.group(1)


@pytest.fixture(scope="module")
def study():
    # The sample runs on the path the environment chooses (BIRKHOFF_CART_STAGE_EVALUATION, else the
    # CPU's): both give the page's bits (docs/developing.md, "Figures that hold on every machine").
    page_stage_evaluation()
    print(f"results sample: stage evaluation {report.stage_evaluation()} (the page's runs: {page_stage_evaluation()})")
    registry = read_registry(str(BIN / "cart_simulate"))
    doc, tasks = load_study(str(STUDY), registry, str(REPO / "config" / "scenes"))
    rows = {row["task_id"]: row for row in latest_rows(read_rows(str(ROWS)))}
    return doc, tasks, rows


def sample_task(tasks, label, method, setting):
    for task in tasks:
        s = task.settings
        if (task.kind.value == "measure" and task.label == label and s.get("method") == method
                and setting in (s.get("step"), s.get("tolerance"))):
            return task
    raise AssertionError(f"the study has no run {label} {method} {setting}: update SAMPLE")


def measured_again(task, reference_row=None):
    """The task's row, run now with the current build as the study runner runs it (1 repetition)."""
    wire = work_precision.wire(task, str(BIN))
    argv = wire["argv"]
    if "--repetitions" in argv:
        argv[argv.index("--repetitions") + 1] = "1"
    return work_precision.run(wire, reference_row)


def glibc_active_cpu_features(environment):
    """The CPU feature words glibc uses in a process with this environment (ld.so --list-diagnostics:
    x86.cpu_features.features[i].active[j]); GLIBC_TUNABLES=glibc.cpu.hwcaps=-FEATURE,... clears bits."""
    listed = subprocess.run([LOADER, "--list-diagnostics"], env=environment, capture_output=True, text=True, check=True)
    return [line for line in listed.stdout.splitlines() if re.match(r"x86\.cpu_features\.features\[\w+\]\.active", line)]


def test_the_cpu_this_sample_runs_as():
    """Says what the sample compares on: glibc's CPU features here and the stage-evaluation path.
    Under GLIBC_TUNABLES (CI's run as another CPU) the features must differ from the machine's own,
    or the tunable named features this glibc does not know and the run tested nothing new."""
    here = glibc_active_cpu_features(os.environ)
    own = glibc_active_cpu_features({k: v for k, v in os.environ.items() if k != "GLIBC_TUNABLES"})
    masked = sum(a != b for a, b in zip(here, own))
    tunables = os.environ.get("GLIBC_TUNABLES", "")
    print(f"results sample: GLIBC_TUNABLES={tunables or '(unset)'}: glibc's active CPU feature words differ from "
          f"the machine's own in {masked} of {len(own)}; stage evaluation {report.stage_evaluation()}")
    assert here and len(here) == len(own), "ld.so --list-diagnostics listed no x86 CPU features"
    if "glibc.cpu.hwcaps" in tunables:
        assert masked > 0, f"GLIBC_TUNABLES={tunables} masked no CPU feature: this glibc does not know those names"


def test_the_page_records_the_commit_it_was_written_from():
    text = PAGE.read_text()
    match = re.search(r"^\| source commit \| `([0-9a-f]{40})`( with changes to \d+ source files?)? \|$", text, re.M)
    assert match, "docs/results.md records no source commit: regenerate it (docs/benchmarks.md)"
    assert not match.group(2), "docs/results.md was written from a tree with uncommitted source changes"
    known = subprocess.run(["git", "-C", str(REPO), "cat-file", "-e", match.group(1) + "^{commit}"],
                           stderr=subprocess.DEVNULL)
    if known.returncode == 128 and not (REPO / ".git").exists():
        pytest.skip("not a git checkout")  # an exported source tree: the commit cannot be looked up
    assert known.returncode == 0, f"docs/results.md names commit {match.group(1)}, which this repository lacks"


def test_the_page_is_generated_from_the_shipped_rows(study):
    _, tasks, rows = study
    ids = {task.id for task in tasks}
    shipped = [row for row in rows.values() if row["task_id"] in ids]
    assert len(shipped) == len(tasks), "bench/results/work_precision/rows.jsonl lacks rows of the study's tasks"
    assert f"Generated by the study runner from {len(shipped)} rows" in PAGE.read_text()


@pytest.mark.parametrize("label", sorted({label for label, _, _ in SAMPLE} - {"paper_special"}))
def test_the_reference_is_measured_again_bit_for_bit(study, label):
    doc, tasks, rows = study
    name = [e["reference"] for e in doc["experiments"] if e["label"] == label][0]
    task = [t for t in tasks if t.kind.value == "reference" and t.label == name][0]
    row = work_precision.run(work_precision.wire(task, str(BIN)))
    assert row.get("outcome") == "ok", row
    assert row["reference_text"] == rows[task.id]["reference_text"], f"reference {name} moved: regenerate docs/results.md"


@pytest.mark.parametrize("label,method,setting", SAMPLE, ids=[f"{l}-{m}-{s:g}" for l, m, s in SAMPLE])
def test_a_sample_row_is_measured_again_bit_for_bit(study, label, method, setting):
    doc, tasks, rows = study
    task = sample_task(tasks, label, method, setting)
    shipped = rows[task.id]
    reference = None
    if not task.settings.get("analytic"):
        reference = [r for r in rows.values() if r.get("type") == "reference" and r.get("label") == task.settings["reference"]][0]
    row = measured_again(task, reference)
    assert row.get("outcome") == shipped.get("outcome"), row.get("stderr_tail") or row
    now = {k: v for k, v in row["result"].items() if k not in TIMES}
    then = {k: v for k, v in shipped["result"].items() if k not in TIMES}
    moved = {k: (then.get(k), now.get(k)) for k in set(now) | set(then) if now.get(k) != then.get(k)}
    assert not moved, (f"{label} {method} {setting:g}: the build no longer gives the row docs/results.md shows "
                       f"(shipped, now): {moved}; regenerate the page (docs/benchmarks.md)")


def test_the_readme_counts_the_position_goals_the_page_judges():
    """README.md's "at least 1.2× cheaper than every peer ... in N of the M position goals it judges"
    is the page's count over the scenes it names (every section but the paper's special case, a
    check of the closed form rather than a race)."""
    met = judged = 0
    for section in re.split(r"^## ", PAGE.read_text(), flags=re.M)[1:]:
        name = section.split("\n", 1)[0].strip()
        verdict = re.search(r"^Goal ratio [0-9.]+: .* at \d+ of \d+ goals(?: \(([^)]*)\))?.*$", section, re.M)
        if name == "paper_special" or verdict is None:
            continue
        header = re.search(r"^\| peer \|(.*)$", section, re.M)
        assert header, f"results.md, section {name}: no goal table"
        goals = [cell.strip() for cell in header.group(1).split("|") if cell.strip().startswith("error ≤")]
        unresolved = re.findall(r"No verdict for (error ≤ [^:]+):", section)
        judged += len([goal for goal in goals if goal not in unresolved])
        met += len([goal for goal in (verdict.group(1) or "").split(", ") if goal.startswith("error ≤")])
    readme = re.sub(r"\s+", " ", (REPO / "README.md").read_text())
    stated = re.search(r"in (\d+) of the (\d+) position goals it judges", readme)
    assert stated, "README.md no longer states how many position goals the benchmark judges"
    assert (int(stated.group(1)), int(stated.group(2))) == (met, judged), \
        f"README.md says {stated.group(1)} of {stated.group(2)} position goals; docs/results.md shows {met} of {judged}"


def test_the_benchmark_pages_verdicts_are_the_pages():
    """docs/benchmarks.md's table of verdicts per position goal (met, missed, no verdict; the worst
    peer's ratio where missed) is what results.md's "against every peer" rows say."""
    verdicts = {}
    for section in re.split(r"^## ", PAGE.read_text(), flags=re.M)[1:]:
        header = re.search(r"^\| peer \|(.*)$", section, re.M)
        every = re.search(r"^\| \*against every peer\* \|(.*)$", section, re.M)
        if header and every:
            goals = [cell.strip() for cell in header.group(1).split("|")]
            cells = [cell.strip() for cell in every.group(1).split("|")]
            verdicts[section.split("\n", 1)[0].strip()] = dict(zip(goals, cells))
    benchmarks = (REPO / "docs" / "benchmarks.md").read_text()
    table = re.search(r"^\| scene \| (1e-3 m \| 1e-6 m \| 1e-8 m) \|\n\|[-|]+\|\n((?:\|.*\n)+)", benchmarks, re.M)
    assert table, "docs/benchmarks.md has no table of verdicts per position goal"
    goals = ["error ≤ 0.001 m", "error ≤ 1e-06 m", "error ≤ 1e-08 m"]
    rows = 0
    for line in table.group(2).strip().split("\n"):
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        scene, duration = re.match(r"(\w+), ([\d ]+) s", cells[0]).groups()
        name = f"{scene}_{duration.replace(' ', '')}s" if scene == "jackknife_whirl" else scene
        assert name in verdicts, f"benchmarks.md names {cells[0]}, which results.md has no section of"
        for goal, cell in zip(goals, cells[1:]):
            page = verdicts[name][goal]
            kind = "met" if page == "met" else "no verdict" if page.startswith("unresolved") else "missed"
            shown = "met" if cell.startswith("met") else "no verdict" if cell.startswith("no verdict") else \
                "missed" if cell.startswith("**missed**") else cell
            assert shown == kind, f"benchmarks.md, {cells[0]}, {goal}: '{cell}'; results.md: '{page}'"
            worst = re.search(r"([0-9.]+×)\)$", page)
            if kind == "missed":
                assert worst and worst.group(1) in cell, f"benchmarks.md, {cells[0]}, {goal}: '{cell}'; results.md: '{page}'"
        rows += 1
    assert rows >= 4


def shown_matches(shown, value):
    """A figure as a page shows it ("1.56e-7", "3.70e6", "0.27", "5e5") is `value` rounded to its digits."""
    match = re.fullmatch(r"(-?\d+)(?:\.(\d+))?(?:e([-+]?\d+))?", shown)
    assert match, f"not a figure: {shown}"
    decimals = len(match.group(2) or "")
    exponent = int(match.group(3) or 0)
    return abs(float(shown) - value) <= 0.5 * 10.0 ** (exponent - decimals) * (1 + 1e-9)


def test_studies_md_quotes_the_whirl_references_of_the_shipped_rows():
    """docs/studies.md's distances between the whirl's reference and its independent check (1000 s
    and 10 000 s, by checkpoint) and the check's CPU time are those of the rows results.md is
    generated from."""
    from birkhoff_cart_study.references import distances
    rows = latest_rows(read_rows(str(ROWS)))
    runs = {(row["type"], row["label"]): row for row in rows if row.get("type") in ("reference", "reference_check")}

    def spread(label):
        return dict(distances(runs[("reference", label)]["reference_text"],
                              runs[("reference_check", label)]["reference_text"]))

    whirl_1000, whirl_10000 = spread("whirl_1000s"), spread("whirl_10000s")
    text = re.sub(r"\s+", " ", (REPO / "docs" / "studies.md").read_text())
    about = re.search(r"the two agree to about ([0-9.e-]+) m over 1000 s", text)
    assert about, "docs/studies.md no longer states the 1000 s whirl reference's spread"
    assert abs(float(about.group(1)) - max(whirl_1000.values())) <= 0.25 * float(about.group(1)), \
        f"docs/studies.md: about {about.group(1)} m over 1000 s; the rows give {max(whirl_1000.values()):.2g} m"
    stated = re.search(r"Over 10 000 s they agree to ([0-9.e-]+) m up to 2000 s, then differ by ([0-9.e-]+) m at "
                       r"5000 s and ([0-9.e-]+) m at 10 000 s", text)
    assert stated, "docs/studies.md no longer states the 10 000 s whirl reference's spread"
    up_to_2000 = max(d for t, d in whirl_10000.items() if t <= 2000.0)
    for shown, value in zip(stated.groups(), (up_to_2000, whirl_10000[5000.0], whirl_10000[10000.0])):
        assert shown_matches(shown, value), f"docs/studies.md states {shown} m, the rows give {value:.3g} m"
    cpu = re.search(r"the check took about (\d+) s of CPU", text)
    check_cpu = runs[("reference_check", "whirl_10000s")]["process_cpu_s"]
    assert cpu and abs(float(cpu.group(1)) - check_cpu) <= 0.1 * check_cpu, \
        f"docs/studies.md: the check took {cpu and cpu.group(1)} s; its row: {check_cpu:.0f} s"


def shown_count_matches(shown, value):
    """A count as a page shows it ("321 700", "831") is `value` rounded to its last non-zero digit."""
    digits = shown.replace(" ", "")
    unit = 10 ** (len(digits) - len(digits.rstrip("0"))) if digits.strip("0") else 1
    return abs(int(digits) - value) <= unit / 2


# docs/benchmarks.md, "Where the peers still win": what it quotes from the shipped rows, as
# (pattern, [(experiment, method, step or tolerance, what of the row) per group]).
PEERS_STILL_WIN = [
    (r"birkhoff_gauss8 under it needs ([\d ]+) evaluations for 1e-6 m over 1000 s \(asked for 3e-5 m, it ends ([0-9.e-]+) m off\) against ([\d ]+) at the best fixed step",
     [("jackknife_whirl_1000s", "birkhoff_gauss8_reversible", 3e-5, "rhs"), ("jackknife_whirl_1000s", "birkhoff_gauss8_reversible", 3e-5, "error"),
      ("jackknife_whirl_1000s", "birkhoff_gauss8", 0.04, "rhs")]),
    (r"bulirsch_stoer needs ([\d ]+) and costs [a-z ]+ per evaluation \((\d+) against (\d+) ns\)",
     [("jackknife_whirl_1000s", "odeint_bulirsch_stoer", 1e-12, "rhs"), ("jackknife_whirl_1000s", "odeint_bulirsch_stoer", 1e-12, "ns"),
      ("jackknife_whirl_1000s", "birkhoff_gauss8_reversible", 3e-5, "ns")]),
    (r"gauss8 adaptive ([\d ]+) evaluations in ([\d ]+) steps \(([0-9.]+) µs each, ([0-9.]+) ms\)",
     [("drive_rr_drag", "birkhoff_gauss8_adaptive", 3e-5, k) for k in ("rhs", "steps", "µs", "ms")]),
    (r"our dopri5 ([\d ]+) evaluations in ([\d ]+) steps \(([0-9.]+) µs each, ([0-9.]+) ms\)",
     [("drive_rr_drag", "dopri5", 1e-8, k) for k in ("rhs", "steps", "µs", "ms")]),
    (r"\(rkf78: ([\d ]+) evaluations, gauss8 adaptive ([\d ]+);",
     [("very_stiff_hinge", "odeint_rkf78", 1e-6, "rhs"), ("very_stiff_hinge", "birkhoff_gauss8_adaptive", 0.1, "rhs")]),
    (r"\(([\d ]+) for gauss8 adaptive at 1e-7 m, which ends ([0-9.e-]+) m off; ([\d ]+) at 1e-8 m; rkf78 ([\d ]+)\)",
     [("very_stiff_hinge", "birkhoff_gauss8_adaptive", 1e-7, "rhs"), ("very_stiff_hinge", "birkhoff_gauss8_adaptive", 1e-7, "error"),
      ("very_stiff_hinge", "birkhoff_gauss8_adaptive", 1e-8, "rhs"), ("very_stiff_hinge", "odeint_rkf78", 1e-11, "rhs")]),
]


def test_the_benchmark_page_quotes_the_shipped_rows():
    """docs/benchmarks.md's explanation of where the peers still win quotes evaluation counts,
    steps, errors and (from the same rows) CPU times per evaluation; they are the shipped rows'."""
    measured = [row for row in latest_rows(read_rows(str(ROWS))) if row.get("type") == "measure"]

    def row_of(label, method, setting):
        found = [row for row in measured if row["label"] == label and row["method"] == method
                 and setting in (row.get("step"), row.get("tolerance"))]
        assert len(found) == 1, f"the rows have {len(found)} runs {label} {method} {setting:g}"
        return found[0]["result"]

    text = re.sub(r"\s+", " ", (REPO / "docs" / "benchmarks.md").read_text())
    for pattern, quoted in PEERS_STILL_WIN:
        match = re.search(pattern, text)
        assert match, f"docs/benchmarks.md no longer says /{pattern}/"
        for shown, (label, method, setting, what) in zip(match.groups(), quoted):
            result = row_of(label, method, setting)
            value = {"rhs": result["rhs_evaluations"], "steps": result["steps"], "error": result["position_error_m"],
                     "ns": 1e9 * result["cpu_median_s"] / result["rhs_evaluations"],
                     "µs": 1e6 * result["cpu_median_s"] / result["rhs_evaluations"], "ms": 1e3 * result["cpu_median_s"]}[what]
            ok = shown_count_matches(shown, value) if what in ("rhs", "steps") else shown_matches(shown, value)
            assert ok, f"docs/benchmarks.md: {shown} ({what} of {label} {method} {setting:g}); the shipped row: {value:.4g}"


def test_the_reversible_whirl_table_of_accuracy_md_is_the_shipped_run():
    """docs/accuracy.md §4.2 quotes bench/results/reversible_whirl.csv, the table the command beside
    it wrote, to the digits it shows (the 10 000 s runs take half a minute: the doc test does not
    rerun them)."""
    import csv
    with open(REPO / "bench" / "results" / "reversible_whirl.csv") as table:
        runs = {(row["control"], float(row["setting"])): row for row in csv.DictReader(table)}
    text = (REPO / "docs" / "accuracy.md").read_text()
    section = text[text.index("### §4.2"):]
    rows = re.findall(r"^\| (fixed|reversible|adaptive) \| ([0-9.e-]+) (?:s|m) \|(.*)\|$", section, re.M)
    assert len(rows) >= 9, "accuracy.md §4.2 no longer has its table"
    columns = ["error_m", "steps", "rhs_evaluations", "cpu_s", "energy_first_tenth_J", "energy_last_tenth_J"]
    for control, setting, rest in rows:
        run = runs.get((control, float(setting)))
        assert run, f"accuracy.md §4.2 shows {control} {setting}, which reversible_whirl.csv lacks"
        cells = [cell.strip().split(" ")[0] for cell in rest.split("|")]
        for column, shown in zip(columns + ["ratio"], cells):
            value = (float(run["energy_last_tenth_J"]) / float(run["energy_first_tenth_J"]) if column == "ratio"
                     else float(run[column]))
            assert shown_matches(shown, value), f"accuracy.md §4.2, {control} {setting}, {column}: {shown}; the run: {value}"


def test_accuracy_md_quotes_the_tolerance_sweep_page():
    """docs/accuracy.md §4.1's summary of the generated tolerance_sweep.md: the runs within 10× of
    their tolerance, and per member the (member, scene) pairs whose work at 1e-3 m is at most a
    quarter of their work at 1e-7 m (from the rhs counts the page shows), with the median ratio."""
    import statistics
    page = (REPO / "docs" / "tolerance_sweep.md").read_text()
    accuracy = re.sub(r"\s+", " ", (REPO / "docs" / "accuracy.md").read_text())
    within = re.search(r"(\d+) of (\d+) judged runs within 10×", page)
    assert within and f"{within.group(1)} of {within.group(2)} judged runs" in accuracy, \
        "accuracy.md §4.1 does not quote tolerance_sweep.md's count of runs within 10× of the tolerance"
    ratios = {}
    for block in re.split(r"^\*\*", page, flags=re.M)[1:]:
        control = "reversible" if "reversible" in block.split(",", 1)[0] else "adaptive"
        for member, cells in re.findall(r"^\| `(\w+)` \|(.*)\|$", block, re.M):
            work = [re.search(r"\((\d+) rhs\)", cell) for cell in cells.split("|")]
            if work[0] and work[4]:  # 1e-3 m and 1e-7 m; a refused scene has neither
                ratios.setdefault((control, member), []).append(int(work[0].group(1)) / int(work[4].group(1)))
    names = {("adaptive", "birkhoff_gauss6"): "Adaptive gauss6", ("adaptive", "dopri5"): "dopri5",
             ("adaptive", "birkhoff_gauss8"): "adaptive gauss8", ("reversible", "birkhoff_gauss8"): "reversible gauss8"}
    assert set(ratios) == set(names), sorted(ratios)
    met = sum(ratio <= 0.25 for values in ratios.values() for ratio in values)
    pairs = sum(len(values) for values in ratios.values())
    assert f"met by {met} of {pairs} (member, scene) pairs" in accuracy, f"tolerance_sweep.md: {met} of {pairs}"
    for key, name in names.items():
        stated = re.search(re.escape(name) + r" (\d+) of (\d+) \(median ([0-9.]+)\)", accuracy)
        assert stated, f"accuracy.md §4.1 no longer states {name}'s count"
        values = ratios[key]
        assert (int(stated.group(1)), int(stated.group(2))) == (sum(r <= 0.25 for r in values), len(values)), \
            f"{name}: accuracy.md says {stated.group(1)} of {stated.group(2)}; tolerance_sweep.md shows " \
            f"{sum(r <= 0.25 for r in values)} of {len(values)}"
        assert shown_matches(stated.group(3), statistics.median(values)), \
            f"{name}: accuracy.md says median {stated.group(3)}; tolerance_sweep.md gives {statistics.median(values):.3f}"


def test_the_benchmark_pages_ratios_at_the_goal_are_the_pages():
    """docs/benchmarks.md's ratios interpolated to exactly 1e-6 m on the 1000 s whirl are the 'at the
    goal' ratios of results.md's race table (the column of error ≤ 1e-06 m)."""
    results = (REPO / "docs" / "results.md").read_text()
    section = results.split("## jackknife_whirl_1000s", 1)[1].split("\n## ", 1)[0]
    text = re.sub(r"\s+", " ", (REPO / "docs" / "benchmarks.md").read_text())
    match = re.search(r"interpolated to exactly 1e-6 m the ratio is ([0-9.]+)× \(bulirsch_stoer\) and ([0-9.]+)× \(rkf78\)", text)
    assert match, "docs/benchmarks.md no longer quotes the whirl's ratios at 1e-6 m"
    for shown, peer in zip(match.groups(), ("odeint_bulirsch_stoer", "odeint_rkf78")):
        row = next((line for line in section.splitlines() if line.startswith(f"| `{peer}` |") and "×" in line), None)
        assert row, f"results.md's jackknife_whirl_1000s race table has no row {peer}"
        cell = row.split("|")[3]  # | peer | 1e-3 | 1e-6 | ...
        at_goal = re.search(r"at the goal ([0-9.]+)×", cell)
        assert at_goal, f"results.md, {peer}, error ≤ 1e-06 m: '{cell.strip()}' has no ratio at the goal"
        assert shown == at_goal.group(1), f"docs/benchmarks.md says {shown}× against {peer}; results.md: {at_goal.group(1)}×"

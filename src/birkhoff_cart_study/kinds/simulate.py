"""cart_simulate runs as tasks, shared by the cli_runs and random_carts kinds: the command line of a
run, its outcome under the CLI contract (cli_contract.py), and the outcome tables of the report.

`wire` runs on the study runner (at submission); `run` and `outcome` on the worker, with the standard
library, task_runner and cli_contract only (Dask sends them by value: workers need the executables,
not this package)."""
import os
import re

from ..cli_contract import judge, with_start_time
from ..race import cpu_text
from ..task_runner import run_task

# task setting → cart_simulate option (the tolerance's option depends on the step control)
OPTIONS = (("step", "--step"), ("duration", "--duration"), ("output_rate", "--output-rate"),
           ("birkhoffian_form", "--birkhoffian-form"), ("random_scene", "--random-scene"))
LAST_ROW = ("t", "x", "y", "theta", "chi", "energy", "p2")  # the last CSV row's columns kept in a row


def wire(task, bin_dir):
    """The task as a worker runs it: cart_simulate on the task's scene (its start time moved for a
    random run) and settings, writing out.csv in the task directory."""
    settings = task.settings
    text = task.scene_text
    if "start_time" in settings:
        text = with_start_time(text, settings["start_time"])
    argv = [os.path.join(bin_dir, "cart_simulate"), "--scene", task.scene, "--integrator", settings["method"],
            "--output", "out.csv", "--quiet"]
    # A study's `tolerances` are dopri5's local tolerance [-], or under a step control (reversible,
    # adaptive) the position error [m] the control aims at (cart_simulate's --position-tolerance);
    # under a step control the rows come at the output rate, and --step is the fixed-step members'.
    controlled = settings.get("step_control", "fixed") != "fixed"
    if "tolerance" in settings:
        argv += ["--position-tolerance" if controlled else "--tolerance", repr(settings["tolerance"])]
    for key, option in OPTIONS:
        if key == "step" and controlled:
            continue
        if key in settings:
            argv += [option, settings[key] if isinstance(settings[key], str) else repr(settings[key])]
    # Always named: a scene may set its own control (very_stiff_hinge.yaml is adaptive), and a
    # fixed-step reference run on it must say fixed.
    argv += ["--step-control", settings.get("step_control", "fixed")]
    return dict(task.wire(), argv=argv, files={task.scene: text})


def _last_row(path):
    """(number of rows, the last row by the header's names) of a CSV, or (0, None)."""
    try:
        with open(path) as f:
            lines = [line for line in f.read().splitlines() if line.strip()]
    except (OSError, UnicodeDecodeError):
        return 0, None
    if len(lines) < 2:
        return 0, None
    try:
        last = {name: float(value) if value else None for name, value in zip(lines[0].split(","), lines[-1].split(","))}
    except ValueError:
        last = None
    return len(lines) - 1, last


def outcome(wire, process):
    """The row's outcome of one run: the contract's verdict (a refusal fails unless the experiment
    expects finish_or_refuse), the number of CSV rows, the last row and the rhs evaluations."""
    row = {}
    count, last = _last_row(process.path("out.csv"))
    if count:
        row["rows"] = count
    if last:
        row["result"] = {k: last.get(k) for k in LAST_ROW}
        rhs = re.search(r"(\d+) rhs evaluations", process.stdout)
        if rhs:
            row["result"]["rhs_evaluations"] = int(rhs.group(1))
    if not process.timed_out:
        verdict, reason = judge(process.status, process.stderr, process.path("out.csv"), wire.get("start_time"),
                                wire.get("duration"), wire.get("step", 0.0))
        if verdict == "refused" and wire.get("expect") != "finish_or_refuse":
            verdict = "failed"
        row["outcome"] = verdict
        if reason:
            row["reason"] = reason
    return row


def run(wire, reference=None):
    """One task on a worker (what the runner submits): its row."""
    return run_task(wire, outcome, reference)


def _cell(text):
    return str(text).replace("|", "/").replace("\n", " ")


def outcome_tables(rows):
    """Markdown lines: outcomes per integrator (with the median CPU per task) and the refusals and
    failures by reason."""
    runs = [r for r in rows if r.get("type") == "simulate"]
    methods = sorted({str(r.get("method")) for r in runs})
    outcomes = sorted({str(r.get("outcome", "failed")) for r in runs})
    lines = ["| integrator | " + " | ".join(outcomes) + " | CPU per task (median) |",
             "|---|" + "---|" * (len(outcomes) + 1)]
    for m in methods:
        mine = [r for r in runs if str(r.get("method")) == m]
        cpus = sorted(r.get("process_cpu_s") or 0.0 for r in mine)
        lines.append("| `%s` | %s | %s |" % (m, " | ".join(str(sum(1 for r in mine if str(r.get("outcome", "failed")) == o))
                                                              for o in outcomes),
                                             cpu_text(cpus[len(cpus) // 2]) if cpus else "—"))
    reasons = {}
    for r in runs:
        if r.get("outcome", "failed") in ("refused", "failed", "timeout"):
            key = (r.get("outcome", "failed"), str(r.get("reason") or "")[:160])
            reasons[key] = reasons.get(key, 0) + 1
    reason_lines = ["| outcome | count | reason (first line) |", "|---|---|---|"]
    for (verdict, reason), n in sorted(reasons.items(), key=lambda kv: (-kv[1], kv[0])):
        reason_lines.append("| %s | %d | %s |" % (verdict, n, _cell(reason)))
    return ["## Outcomes", "", *lines, "", "Refusals and failures by reason:", "", *reason_lines, ""]

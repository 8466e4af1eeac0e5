"""Tables and plots from a study's rows: one code path, whether the rows came from one machine or
a hundred. The page records the command, the date, the machine, its load and the workers, so
every number in it says where it came from. Ratios are computed from process CPU time."""
import datetime
import math
import os
import platform

from birkhoff_cart_study.race import GOAL_RATIO, cpu_text, race

POSITION_GOALS = (1e-3, 1e-6, 1e-8)   # final position error of the hinge B [m]
ENERGY_GOALS = (1e-6, 1e-10)          # max relative energy-balance residual [-]
ENERGY_GOALS_J = (1e-11,)             # max absolute energy-balance residual over the whole run [J]
GOALS = ([("error", g, "error ≤ %g m" % g) for g in POSITION_GOALS]
         + [("energy_rel", g, "energy ≤ %g T*₀" % g) for g in ENERGY_GOALS]
         + [("energy", g, "energy ≤ %g J" % g) for g in ENERGY_GOALS_J])   # (run key, goal, column title)
EQUAL_ERROR = 1e-6                    # [m], the error at which rhs per simulated second is compared


def is_birkhoffian(method):
    return method.startswith("birkhoff")


def _setting(row):
    if "step" in row:
        return "h=%g" % row["step"]
    text = "tol=%g" % row["tolerance"]
    if row.get("simulator_step") not in (None, 0.1):
        text += ", sim step %g" % row["simulator_step"]
    return text


def _method(row):
    if row.get("simulator_step") not in (None, 0.1):
        return "%s_sim%gs" % (row["method"], row["simulator_step"])
    return row["method"]


def measurements(rows):
    """The successful measurement rows, flattened: method, setting, CPU, errors, rhs, checkpoints."""
    out = []
    for row in rows:
        if row.get("type") != "measure" or row.get("outcome") != "ok":
            continue
        r = row["result"]
        out.append({"label": row["label"], "method": _method(row), "setting": _setting(row),
                    "cpu": r["cpu_median_s"], "wall": r["wall_median_s"], "error": r["position_error_m"],
                    "energy_rel": r["max_energy_residual_rel"], "energy": r["max_energy_residual_J"],
                    "p2": r["max_p2_residual"], "rhs": r["rhs_evaluations"], "duration": r["duration_s"],
                    "iterations": r["iterations"], "steps": r["steps"], "checkpoints": r.get("checkpoints", []),
                    "worker": row.get("worker"), "load": row.get("load_average_1min")})
    return out


def cheapest(runs, key, goal):
    """The run of least CPU time whose `key` is ≤ goal (None when none reaches it)."""
    reaching = [r for r in runs if r[key] is not None and r[key] <= goal]
    return min(reaching, key=lambda r: r["cpu"]) if reaching else None


def accuracy_tables(runs):
    """Markdown: per method the cheapest run reaching each goal; the race of the best Birkhoffian
    member against each peer (race.py) and its summary line; rhs per simulated second at equal error."""
    methods = sorted({r["method"] for r in runs}, key=lambda m: (not is_birkhoffian(m), m))
    by_method = {m: [r for r in runs if r["method"] == m] for m in methods}
    lines = ["| method | " + " | ".join(title for _, _, title in GOALS) + " |", "|---|" + "---|" * len(GOALS)]
    for m in methods:
        cells = []
        for key, g, _ in GOALS:
            best = cheapest(by_method[m], key, g)
            cells.append("%s (%s)" % (cpu_text(best["cpu"]), best["setting"]) if best else "—")
        lines.append("| `%s` | %s |" % (m, " | ".join(cells)))
    table = "\n".join(lines)

    ratios, summary = race(runs, GOALS, is_birkhoffian)

    rhs_lines = ["| method | rhs / simulated s | CPU | setting |", "|---|---|---|---|"]
    for m in methods:
        best = cheapest(by_method[m], "error", EQUAL_ERROR)
        if best:
            rhs_lines.append("| `%s` | %.4g | %s | %s |" % (m, best["rhs"] / best["duration"], cpu_text(best["cpu"]), best["setting"]))
    return table, ratios, summary, "\n".join(rhs_lines)


def plot_work_precision(runs, label, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 6))
    for m in sorted({r["method"] for r in runs}):
        pts = sorted((r["cpu"], r["error"]) for r in runs if r["method"] == m and r["error"] and r["error"] > 0)
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if is_birkhoffian(m) else "s--", label=m,
                      linewidth=2 if is_birkhoffian(m) else 1, markersize=4)
    ax.set_xlabel("CPU time per run [s] (median)")
    ax.set_ylabel("final position error of B [m]")
    ax.set_title("work–precision: %s" % label)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_error_vs_time(runs, label, path):
    """Per method, the cheapest run that ends within EQUAL_ERROR: its error and energy residual over time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    drawn = False
    for m in sorted({r["method"] for r in runs}):
        best = cheapest([r for r in runs if r["method"] == m], "error", EQUAL_ERROR)
        if not best or len(best["checkpoints"]) < 3:
            continue
        t = [c[0] for c in best["checkpoints"]]
        style = "-" if is_birkhoffian(m) else "--"
        ax1.loglog(t, [max(c[1] or 1e-17, 1e-17) for c in best["checkpoints"]], style, label="%s %s" % (m, best["setting"]))
        ax2.loglog(t, [max(c[2] or 1e-17, 1e-17) for c in best["checkpoints"]], style, label=m)
        drawn = True
    if not drawn:
        plt.close(fig)
        return False
    ax1.set_xlabel("t [s]"), ax1.set_ylabel("position error [m]")
    ax2.set_xlabel("t [s]"), ax2.set_ylabel("max |energy-balance residual| so far [J]")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7)
    fig.suptitle("error versus time, %s (each method's cheapest run ending within %g m)" % (label, EQUAL_ERROR))
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return True


def machine():
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return "%s, %d cores, %s" % (model, os.cpu_count(), platform.system())


def simulate_tables(rows):
    """CLI studies: outcomes per integrator and the refusal or failure reasons."""
    runs = [r for r in rows if r.get("type") == "simulate"]
    methods = sorted({r["method"] for r in runs})
    outcomes = sorted({r.get("outcome", "failed") for r in runs})
    lines = ["| integrator | " + " | ".join(outcomes) + " | CPU per task (median) |",
             "|---|" + "---|" * (len(outcomes) + 1)]
    for m in methods:
        mine = [r for r in runs if r["method"] == m]
        cpus = sorted(r.get("process_cpu_s", 0.0) for r in mine)
        lines.append("| `%s` | %s | %s |" % (m, " | ".join(str(sum(1 for r in mine if r.get("outcome") == o)) for o in outcomes),
                                             cpu_text(cpus[len(cpus) // 2]) if cpus else "—"))
    reasons = {}
    for r in runs:
        if r.get("outcome") in ("refused", "failed", "timeout"):
            key = (r["outcome"], (r.get("reason") or "")[:160])
            reasons[key] = reasons.get(key, 0) + 1
    reason_lines = ["| outcome | count | reason (first line) |", "|---|---|---|"]
    for (outcome, reason), n in sorted(reasons.items(), key=lambda kv: -kv[1]):
        reason_lines.append("| %s | %d | %s |" % (outcome, n, reason.replace("|", "/")))
    return "\n".join(lines), "\n".join(reason_lines)


def reference_distances(reference_text, check_text):
    """[(t, distance of the hinge B between the two runs [m])] at every checkpoint of both files."""
    def states(text):
        rows = {}
        for line in text.splitlines():
            if line and not line.startswith(("#", "t,")):
                t, x, y = (float(v) for v in line.split(",")[:3])
                rows[t] = (x, y)
        return rows
    a, b = states(reference_text), states(check_text)
    return [(t, math.hypot(a[t][0] - b[t][0], a[t][1] - b[t][1])) for t in sorted(a) if t in b]


def reference_tables(rows):
    """Runs judged against a reference of their own scene (cart_simulate studies with `reference`):
    error at the end / tolerance per scene, member and tolerance, '?' where the reference and its
    check disagree by more than a tenth of the tolerance."""
    out, within, total, worst = [], 0, 0, 0.0
    simulate = [r for r in rows if r.get("type") == "simulate"]
    for scene in sorted({r["scene"] for r in simulate if r.get("judged_against_reference")}):
        refs = {r["role"]: r for r in simulate if r["scene"] == scene and r.get("role")}
        ref, check = refs.get("reference"), refs.get("reference_check")
        if not (ref and check and ref.get("outcome") == "ok" and check.get("outcome") == "ok"):
            out += ["**%s**: the reference failed" % scene, ""]
            continue
        spread = math.hypot(ref["result"]["x"] - check["result"]["x"], ref["result"]["y"] - check["result"]["y"])
        runs = [r for r in simulate if r["scene"] == scene and r.get("judged_against_reference")]
        tolerances = sorted({r["tolerance"] for r in runs}, reverse=True)
        out += ["**%s**: reference %s at h = %.3g s and h/2 agree to %.2g m." % (scene, ref["method"], check["step"] * 2, spread), "",
                "| member | " + " | ".join("%g" % t for t in tolerances) + " |", "|---|" + "---|" * len(tolerances)]
        for method in sorted({r["method"] for r in runs}):
            cells = []
            for t in tolerances:
                run = next((r for r in runs if r["method"] == method and r["tolerance"] == t), None)
                if run is None or run.get("outcome") != "ok":
                    cells.append("failed" if run else "—")
                    continue
                error = math.hypot(run["result"]["x"] - check["result"]["x"], run["result"]["y"] - check["result"]["y"])
                ratio = error / t
                total += 1
                within += ratio <= 10.0
                worst = max(worst, ratio)
                rhs = run["result"].get("rhs_evaluations")
                cells.append("%.2g%s (%s rhs)" % (ratio, "" if 10 * spread <= t else "?", rhs if rhs is not None else "?"))
            out.append("| `%s` | %s |" % (method, " | ".join(cells)))
        out.append("")
    if total:
        out.insert(0, "Final position error / tolerance (and rhs evaluations): %d of %d runs within 10× of the "
                      "tolerance, worst %.3g ('?': the reference is not 10× tighter than that tolerance)." % (within, total, worst))
        out.insert(1, "")
    return "\n".join(out)


def write_report(study, rows, page_path, command, summary, labels=()):
    """Writes the results page (markdown) and its plots beside it (<page stem>_*.png)."""
    stem = os.path.splitext(page_path)[0]
    directory = os.path.dirname(os.path.abspath(page_path))
    os.makedirs(directory, exist_ok=True)
    loads = [r.get("load_average_1min") for r in rows if r.get("load_average_1min") is not None]
    workers = sorted({r.get("workers") for r in rows if r.get("workers")})
    cpu_total = sum(r.get("process_cpu_s", 0.0) or 0.0 for r in rows)
    out = ["# Results: %s" % study["name"], "",
           "Generated by the study runner from %d rows; do not edit by hand. Regenerate with:" % len(rows), "",
           "    %s" % command, "",
           "| | |", "|---|---|",
           "| written | %s |" % datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "| machine | %s |" % machine(),
           "| Dask workers | %s |" % ", ".join(str(w) for w in workers),
           "| load average while running (1 min, over the tasks) | %s |" % (
               "%.1f–%.1f (median %.1f)" % (min(loads), max(loads), sorted(loads)[len(loads) // 2]) if loads else "—"),
           "| process CPU time, all tasks | %.1f s |" % cpu_total,
           "| last run | %s |" % summary.replace("|", "/"), ""]
    if study.get("description"):
        out += [study["description"].strip(), ""]
    out += ["Times are each run's median process CPU time over its repetitions (fair within one study: "
            "every task runs single-threaded in its own process); ratios are peer CPU / best Birkhoffian CPU, "
            "so a ratio above 1 means the Birkhoffian member is cheaper. Errors are deterministic and do not "
            "depend on the number of workers.", ""]
    references = [r for r in rows if r.get("type") == "reference"]
    checks = {r["label"]: r for r in rows if r.get("type") == "reference_check"}
    if references:
        out += ["## References", "",
                "| reference | scene, span | reference setting vs its check | their distance, largest over the checkpoints (at the end) [m] |",
                "|---|---|---|---|"]
        for r in references:
            check = checks.get(r["label"])
            if r.get("outcome") == "ok" and check and check.get("outcome") == "ok":
                d = reference_distances(r["reference_text"], check["reference_text"])
                out.append("| %s | %s, %g s | %s vs %s | %.2g (%.2g) |" % (
                    r["label"], r["scene"], r["duration"], r["result"]["reference"], check["result"]["reference"],
                    max(x for _, x in d), d[-1][1]))
            else:
                out.append("| %s | %s | failed | %s |" % (r["label"], r.get("reference_kind"),
                                                         (r.get("reason") or (check or {}).get("reason") or "no check row")))
        out.append("")
    runs = measurements(rows)
    present = {r["label"] for r in runs}
    for label in [l for l in labels if l in present] + sorted(present - set(labels)):
        mine = [r for r in runs if r["label"] == label]
        table, ratios, summary_line, rhs = accuracy_tables(mine)
        png = "%s_%s.png" % (os.path.basename(stem), label)
        plot_work_precision(mine, label, os.path.join(directory, png))
        out += ["## %s" % label, "", "![work–precision %s](%s)" % (label, png), "",
                "Cheapest run (CPU time, setting) reaching each goal:", "", table, "",
                "Best Birkhoffian member against each peer, each at its cheapest run reaching the goal (peer CPU / "
                "best Birkhoffian CPU; met: at least %g×; 'at the goal': the same ratio between the two "
                "work–precision curves interpolated to exactly the goal; docs/benchmarks.md):" % GOAL_RATIO, "",
                ratios, "", summary_line, "",
                "Right-hand-side evaluations per simulated second at equal error (%g m):" % EQUAL_ERROR, "", rhs, ""]
        vs_time = "%s_%s_vs_time.png" % (os.path.basename(stem), label)
        if plot_error_vs_time(mine, label, os.path.join(directory, vs_time)):
            out += ["![error versus time %s](%s)" % (label, vs_time), ""]
    if any(r.get("type") == "simulate" for r in rows):
        outcomes, reasons = simulate_tables(rows)
        out += ["## Outcomes", "", outcomes, "", "Refusals and failures by reason:", "", reasons, ""]
        judged = reference_tables(rows)
        if judged:
            out += ["## Against the reference", "", judged, ""]
    stepless = [r for r in rows if r.get("outcome") == "step_failed"]
    if stepless:
        out += ["## Runs whose step failed", "",
                "A measured result, not a failure of the study: the method cannot integrate the run at that setting.", "",
                "| task | method | setting | reason |", "|---|---|---|---|"]
        for r in stepless:
            out.append("| %s | `%s` | %s | %s |" % (r["label"], r.get("method", ""), _setting(r),
                                                    (r.get("reason") or "").replace("|", "/")[:200]))
        out.append("")
    failed = [r for r in rows if r.get("outcome") in ("failed", "timeout") and r.get("type") != "simulate"]
    if failed:
        out += ["## Failed tasks", "", "| task | method | setting | outcome | reason |", "|---|---|---|---|---|"]
        for r in failed:
            out.append("| %s | %s | %s | %s | %s |" % (r["label"], r.get("method", ""), _setting(r) if "step" in r or "tolerance" in r else "",
                                                       r["outcome"], (r.get("reason") or "").replace("|", "/")[:200]))
        out.append("")
    with open(page_path, "w") as f:
        f.write("\n".join(out))
    return page_path

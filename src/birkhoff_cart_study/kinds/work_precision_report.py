"""The work_precision kind's tables and plots: the references and what they resolve, per experiment
the cheapest run reaching each goal, the race of the best Birkhoffian member against each peer
(race.py), rhs evaluations at equal error, and the work–precision and error-versus-time plots.

A position goal the experiment's reference does not resolve (references.py) is "unresolved" in
every table (no run, no ratio, no verdict) and in the plots (the band below the reference's
resolution is shaded and the goal's line is grey)."""
import math
import os

from ..race import GOAL_RATIO, cpu_text, race
from ..references import RESOLUTION, Resolution, distances

POSITION_GOALS = (1e-3, 1e-6, 1e-8)   # final position error of the hinge B [m]
ENERGY_GOALS = (1e-6, 1e-10)          # max relative energy-balance residual [-]
ENERGY_GOALS_J = (1e-11,)             # max absolute energy-balance residual over the whole run [J]
GOALS = ([("error", g, "error ≤ %g m" % g) for g in POSITION_GOALS]
         + [("energy_rel", g, "energy ≤ %g T*₀" % g) for g in ENERGY_GOALS]
         + [("energy", g, "energy ≤ %g J" % g) for g in ENERGY_GOALS_J])   # (run key, goal, column title)
EQUAL_ERROR = 1e-6                    # [m], the error at which rhs per simulated second is compared
SIMULATOR_STEP_DEFAULT = 0.1          # [s] our dopri5's Simulation step unless the run sets another


def is_birkhoffian(method):
    return method.startswith("birkhoff")


def _cell(text):
    return str(text).replace("|", "/").replace("\n", " ")


def setting_text(row, run_settings):
    """The run's settings as the tables show them: "h=0.01", "tol=1e-08, sim step 10"."""
    parts = []
    for setting in run_settings.values():
        value = row.get(setting.field)
        if value is None or (setting.field == "simulator_step" and value == SIMULATOR_STEP_DEFAULT):
            continue
        parts.append(("%s=%g" if setting.primary else "%s %g") % (setting.label, value))
    return ", ".join(parts) or "—"


def _curve(row):
    """The curve a run belongs to: its method, our dopri5 split by its Simulation step."""
    if row.get("simulator_step") not in (None, SIMULATOR_STEP_DEFAULT):
        return "%s_sim%gs" % (row["method"], row["simulator_step"])
    return str(row.get("method"))


def measurements(rows, run_settings):
    """The successful measurement rows, flattened: method, setting, CPU, errors, rhs, checkpoints."""
    out = []
    for row in rows:
        result = row.get("result")
        if row.get("type") != "measure" or row.get("outcome") != "ok" or not isinstance(result, dict):
            continue
        out.append({"label": row.get("label"), "method": _curve(row), "setting": setting_text(row, run_settings),
                    "cpu": result.get("cpu_median_s"), "wall": result.get("wall_median_s"),
                    "error": result.get("position_error_m"), "energy_rel": result.get("max_energy_residual_rel"),
                    "energy": result.get("max_energy_residual_J"), "p2": result.get("max_p2_residual"),
                    "rhs": result.get("rhs_evaluations"), "duration": result.get("duration_s") or row.get("duration"),
                    "checkpoints": result.get("checkpoints") or [], "reference": row.get("reference"),
                    "analytic": bool(row.get("analytic"))})
    return out


def cheapest(runs, key, goal):
    """The run of least CPU time whose `key` is ≤ goal (None when none reaches it)."""
    reaching = [r for r in runs if r.get(key) is not None and r["cpu"] is not None and r[key] <= goal]
    return min(reaching, key=lambda r: r["cpu"]) if reaching else None


def resolutions(rows):
    """{reference name: Resolution} from the reference and check rows."""
    out = {}
    checks = {r.get("label"): r for r in rows if r.get("type") == "reference_check"}
    for ref in (r for r in rows if r.get("type") == "reference"):
        name, check = ref.get("label"), checks.get(ref.get("label"))
        if ref.get("outcome") != "ok":
            out[name] = Resolution(name, failure="failed (%s)" % (ref.get("reason") or ref.get("outcome")))
        elif not check:
            out[name] = Resolution(name, failure="has no check row (run the study again to run its check)")
        elif check.get("outcome") != "ok":
            out[name] = Resolution(name, failure="could not be checked: its check failed (%s)"
                                   % (check.get("reason") or check.get("outcome")))
        else:
            try:
                out[name] = Resolution(name, distances(ref["reference_text"], check["reference_text"]))
            except (KeyError, ValueError, TypeError):
                out[name] = Resolution(name, failure="has an unreadable reference file")
    return out


def unresolved_goals(label, runs, resolution):
    """{goal index: why unresolved} for one experiment's runs."""
    if not runs or runs[0]["analytic"]:
        return {}
    if resolution is None:
        resolution = Resolution(runs[0]["reference"], failure="has no row")
    duration = max(r["duration"] or 0.0 for r in runs)
    out = {}
    for index, (key, goal, title) in enumerate(GOALS):
        if key == "error":
            why = resolution.why_unresolved(goal, duration, "%s, %s" % (label, title))
            if why:
                out[index] = why
    return out


def accuracy_tables(runs, unresolved, error_floor=0.0):
    """Markdown: per method the cheapest run reaching each goal ('unresolved' where the reference
    cannot tell); the race (race.py) and its summary; rhs per simulated second at equal error."""
    methods = sorted({r["method"] for r in runs}, key=lambda m: (not is_birkhoffian(m), m))
    by_method = {m: [r for r in runs if r["method"] == m] for m in methods}
    lines = ["| method | " + " | ".join(title for _, _, title in GOALS) + " |", "|---|" + "---|" * len(GOALS)]
    for m in methods:
        cells = []
        for index, (key, g, _) in enumerate(GOALS):
            best = None if index in unresolved else cheapest(by_method[m], key, g)
            cells.append("unresolved" if index in unresolved else
                         "%s (%s)" % (cpu_text(best["cpu"]), best["setting"]) if best else "—")
        lines.append("| `%s` | %s |" % (m, " | ".join(cells)))
    ratios, summary = race(runs, GOALS, is_birkhoffian, unresolved, error_floor)
    equal_index = next(i for i, (key, g, _) in enumerate(GOALS) if key == "error" and g == EQUAL_ERROR)
    rhs_lines = ["| method | rhs / simulated s | CPU | setting |", "|---|---|---|---|"]
    if equal_index in unresolved:
        rhs_lines.append("| unresolved | | | the reference does not resolve %g m |" % EQUAL_ERROR)
    else:
        for m in methods:
            best = cheapest(by_method[m], "error", EQUAL_ERROR)
            if best and best["rhs"] is not None and best["duration"]:
                rhs_lines.append("| `%s` | %.4g | %s | %s |" % (m, best["rhs"] / best["duration"], cpu_text(best["cpu"]),
                                                               best["setting"]))
    return "\n".join(lines), ratios, summary, "\n".join(rhs_lines)


def _shade_unresolved(ax, floor, unresolved_goals_m):
    """The band below the reference's resolution (RESOLUTION × its spread) and the goal lines,
    grey and dashed where unresolved."""
    if floor:
        ax.axhspan(1e-30, min(floor, 1e30), color="0.85", zorder=0,
                   label="unresolved: the reference could not be checked" if math.isinf(floor) else
                   "unresolved: below %g × the reference's spread (%.2g m)" % (RESOLUTION, floor / RESOLUTION))
    for goal in POSITION_GOALS:
        grey = goal in unresolved_goals_m
        ax.axhline(goal, color="0.6" if grey else "0.3", linestyle="--" if grey else ":", linewidth=0.8)


def plot_work_precision(runs, label, path, floor, unresolved_goals_m):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 6))
    drawn = False
    for m in sorted({r["method"] for r in runs}):
        pts = sorted((r["cpu"], r["error"]) for r in runs if r["method"] == m and r["cpu"] and r["error"]
                     and r["error"] > 0)
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if is_birkhoffian(m) else "s--", label=m,
                      linewidth=2 if is_birkhoffian(m) else 1, markersize=4)
            drawn = True
    if not drawn:
        ax.set_xscale("log")
        ax.set_yscale("log")
    bottom, top = ax.get_ylim()
    _shade_unresolved(ax, floor, unresolved_goals_m)
    ax.set_ylim(min(bottom, min(POSITION_GOALS) / 10), max(top, max(POSITION_GOALS) * 10))
    ax.set_xlabel("CPU time per run [s] (median)")
    ax.set_ylabel("final position error of B [m]")
    ax.set_title("work–precision: %s%s" % (label, "\n(no verdict for errors ≤ %s: the reference does not resolve them)"
                                            % ", ".join("%g m" % g for g in sorted(unresolved_goals_m, reverse=True))
                                            if unresolved_goals_m else ""))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_error_vs_time(runs, label, path, spreads):
    """Per method, the cheapest run that ends within EQUAL_ERROR: its error and energy residual over
    time, the reference's resolution (RESOLUTION × its spread at each checkpoint) shaded."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    drawn = False
    for m in sorted({r["method"] for r in runs}):
        best = cheapest([r for r in runs if r["method"] == m], "error", EQUAL_ERROR)
        points = [c for c in (best or {}).get("checkpoints", []) if isinstance(c, list) and len(c) >= 3]
        if len(points) < 3:
            continue
        t = [c[0] for c in points]
        style = "-" if is_birkhoffian(m) else "--"
        ax1.loglog(t, [max(c[1] or 1e-17, 1e-17) for c in points], style, label="%s %s" % (m, best["setting"]))
        ax2.loglog(t, [max(c[2] or 1e-17, 1e-17) for c in points], style, label=m)
        drawn = True
    if not drawn:
        plt.close(fig)
        return False
    shown = [(t, RESOLUTION * d) for t, d in spreads if t > 0 and d > 0]
    if shown:
        ax1.fill_between([t for t, _ in shown], 1e-17, [f for _, f in shown], color="0.85", zorder=0,
                         label="unresolved: below %g × the reference's spread" % RESOLUTION)
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


def _reference_lines(rows, found):
    references = [r for r in rows if r.get("type") == "reference"]
    if not references:
        return []
    checks = {r.get("label"): r for r in rows if r.get("type") == "reference_check"}
    out = ["## References", "",
           "Each reference is checked against an independent run (references.py); it judges a position goal only "
           "where the two agree to a tenth of it.", "",
           "| reference | scene, span | reference vs its check | their distance, largest over the checkpoints "
           "(at the end) [m] | resolves errors down to |", "|---|---|---|---|---|"]
    for r in references:
        resolution = found.get(r.get("label"))
        check = checks.get(r.get("label")) or {}
        if resolution is not None and not resolution.failure and resolution.spreads:
            largest = max(d for _, d in resolution.spreads)
            out.append("| %s | %s, %g s | %s vs %s | %.2g (%.2g) | %.2g m |" % (
                r.get("label"), r.get("scene"), r.get("duration") or 0.0, (r.get("result") or {}).get("reference"),
                (check.get("result") or {}).get("reference"), largest, resolution.spreads[-1][1], RESOLUTION * largest))
        else:
            out.append("| %s | %s, %s | %s | — | nothing: it %s |" % (
                r.get("label"), r.get("scene"), r.get("reference_kind"), "failed" if r.get("outcome") != "ok" else "unchecked",
                _cell(resolution.failure if resolution else "has no row")[:200]))
    return out + [""]


def report(study, rows, directory, stem, run_settings):
    """The kind's sections of the results page and its plots: (markdown lines, unresolved goals)."""
    found = resolutions(rows)
    out = _reference_lines(rows, found)
    runs = measurements(rows, run_settings)
    present = {r["label"] for r in runs}
    order = [l for l in study.get("labels", []) if l in present] + sorted(present - set(study.get("labels", [])))
    unresolved_all = []
    for label in order:
        mine = [r for r in runs if r["label"] == label]
        resolution = found.get(mine[0]["reference"])
        unresolved = unresolved_goals(label, mine, resolution)
        unresolved_all += list(unresolved.values())
        floor = None
        spreads = []
        if resolution is not None and not mine[0]["analytic"]:
            duration = max(r["duration"] or 0.0 for r in mine)
            spreads = [(t, d) for t, d in resolution.spreads if t <= duration * (1 + 1e-12)]
            spread = resolution.spread(duration)
            floor = RESOLUTION * spread if spread is not None and not resolution.failure else math.inf
        elif not mine[0]["analytic"]:
            floor = math.inf
        table, ratios, summary_line, rhs = accuracy_tables(mine, unresolved, floor or 0.0)
        png = "%s_%s.png" % (stem, label)
        unresolved_m = {GOALS[i][1] for i in unresolved}
        plot_work_precision(mine, label, os.path.join(directory, png), floor, unresolved_m)
        out += ["## %s" % label, ""]
        if unresolved:
            out += ["**No verdict for %s**: %s." % (", ".join(GOALS[i][2] for i in sorted(unresolved)),
                                                    "; ".join(unresolved[i] for i in sorted(unresolved))), ""]
        out += ["![work–precision %s](%s)" % (label, png), "",
                "Cheapest run (CPU time, setting) reaching each goal:", "", table, "",
                "Best Birkhoffian member against each peer, each at its cheapest run reaching the goal (peer CPU / "
                "best Birkhoffian CPU; met: at least %g×; 'at the goal': the same ratio between the two "
                "work–precision curves interpolated to exactly the goal; docs/benchmarks.md):" % GOAL_RATIO, "",
                ratios, "", summary_line, "",
                "Right-hand-side evaluations per simulated second at equal error (%g m):" % EQUAL_ERROR, "", rhs, ""]
        vs_time = "%s_%s_vs_time.png" % (stem, label)
        if plot_error_vs_time(mine, label, os.path.join(directory, vs_time), spreads):
            out += ["![error versus time %s](%s)" % (label, vs_time), ""]
    stepless = [r for r in rows if r.get("outcome") == "step_failed"]
    if stepless:
        out += ["## Runs whose step failed", "",
                "A measured result, not a failure of the study: the method cannot integrate the run at that setting.", "",
                "| task | method | setting | reason |", "|---|---|---|---|"]
        for r in stepless:
            out.append("| %s | `%s` | %s | %s |" % (r.get("label"), r.get("method", ""), setting_text(r, run_settings),
                                                    _cell(r.get("reason") or "")[:200]))
        out.append("")
    # A reference that could not run leaves its experiments without measurements: name them too.
    for name, resolution in found.items():
        if resolution.failure and not any(r["reference"] == name for r in runs):
            unresolved_all.append("reference %s %s" % (name, resolution.failure))
    return out, unresolved_all

#!/usr/bin/python3
"""Plots and Markdown tables from the work_precision CSVs (issue 6).

    /usr/bin/python3 bench/bench_plot.py [RESULTS_DIR]      (default bench/results)

Reads work_precision.csv, reference_check.csv, long_run.csv, paper_relative_error.csv written by
the work_precision executable and writes, beside them:
  work_precision_<scene>.png  final position error [m] and max energy-balance residual [J]
                              against median wall time [s], log-log, one line per method
  long_run.png                |energy residual| [J] and |p2 residual| against simulated time (1000 s)
  paper_figures.png           relative error of pi1 against the closed form, tau = 0.001 (figs. 1-2)
  work_precision.md           cost-to-accuracy table, odeint ratios, targets, full per-run table
Uses Debian's python3-matplotlib (Agg backend, no display needed).
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 72  # keeps each PNG well under 200 kB
METHOD_STYLE = {  # colour, marker, line style
    "birkhoff2": ("tab:blue", "o", "-"),
    "birkhoff4": ("tab:green", "s", "-"),
    "midpoint": ("tab:cyan", "v", ":"),
    "rk2": ("tab:orange", "^", "-"),
    "rk4": ("tab:red", "D", "-"),
    "dopri5": ("tab:purple", "P", "-"),
    "odeint_rk4": ("tab:red", "x", "--"),
    "odeint_dopri5": ("tab:purple", "*", "--"),
}
METHOD_ORDER = list(METHOD_STYLE)
ENERGY_TARGET = 1e-8  # [J] issue 6 target for jackknife_whirl over 1000 s
POSITION_TARGETS = (1e-3, 1e-6)  # [m]


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def read_rows(path):
    with open(path, newline="") as handle:
        lines = [line for line in handle if not line.startswith("#")]
    return list(csv.DictReader(lines))


def ok_rows(rows):
    return [r for r in rows if r["status"] == "ok"]


def positive(values):
    return [v if (v > 0 and math.isfinite(v)) else math.nan for v in values]


def plot_work_precision(rows, checks, scene, out_dir):
    runs = [r for r in ok_rows(rows) if r["scene"] == scene]
    floor = [number(c["position_difference_m"]) for c in checks if c["scene"] == scene]
    figure, axes = plt.subplots(1, 2, figsize=(10, 4))
    panels = (("position_error_m", "final position error of B [m]"),
              ("max_energy_residual_J", "max |T* - T*0 - W| over the run [J]"))
    for axis, (column, label) in zip(axes, panels):
        for method in METHOD_ORDER:
            mine = [r for r in runs if r["method"] == method]
            if not mine:
                continue
            colour, marker, style = METHOD_STYLE[method]
            time = [number(r["wall_median_s"]) for r in mine]
            error = positive([number(r[column]) for r in mine])
            axis.loglog(time, error, color=colour, marker=marker, linestyle=style, label=method, markersize=5)
        if column == "position_error_m" and floor and floor[0] > 0:
            axis.axhline(floor[0], color="grey", linewidth=0.8, linestyle="--")
            axis.annotate("reference: dopri5 1e-13 vs 1e-12", (0.02, floor[0]), xycoords=("axes fraction", "data"),
                          fontsize=7, color="grey", va="bottom")
        if column == "max_energy_residual_J":
            axis.axhline(ENERGY_TARGET, color="black", linewidth=0.8, linestyle="--")
        axis.set_xlabel("median wall time [s]")
        axis.set_ylabel(label)
        axis.grid(True, which="major", alpha=0.4)
    axes[0].legend(fontsize=8)
    figure.suptitle(f"work-precision: {scene}")
    figure.tight_layout()
    path = os.path.join(out_dir, f"work_precision_{scene}.png")
    figure.savefig(path, dpi=DPI)
    plt.close(figure)
    return path


def running_max(values):
    result, peak = [], 0.0
    for v in values:
        peak = max(peak, v)
        result.append(peak)
    return result


def plot_long_run(out_dir):
    path = os.path.join(out_dir, "long_run.csv")
    if not os.path.exists(path):
        return None
    rows = read_rows(path)
    if not rows:
        return None
    series = defaultdict(list)
    for r in rows:
        series[r["method"]].append(r)
    figure, axes = plt.subplots(1, 2, figsize=(10, 4))
    for method in METHOD_ORDER:
        if method not in series:
            continue
        colour, _, style = METHOD_STYLE[method]
        data = series[method]
        first = data[0]
        setting = f"h={number(first['step_size_s']):g} s" if method != "dopri5" else f"tol={first['tolerance']}"
        label = f"{method} ({setting}, {number(first['cpu_median_s']):.2f} s)"
        t = [number(r["t"]) for r in data]
        axes[0].semilogy(t, positive(running_max([abs(number(r["energy_residual_J"])) for r in data])),
                         color=colour, linestyle=style, label=label, linewidth=1.5)
        axes[1].semilogy(t, positive(running_max([abs(number(r["p2_residual"])) for r in data])), color=colour,
                         linestyle=style, label=label, linewidth=1.5)
    axes[0].axhline(ENERGY_TARGET, color="black", linewidth=0.8, linestyle="--")
    axes[0].set_ylabel("running max |T* - T*0 - W| [J]")
    axes[1].set_ylabel("running max |p2 - p2_0 - I2| [kg m^2/s]")
    for axis in axes:
        axis.set_xlabel("simulated time [s]")
        axis.grid(True, alpha=0.4)
    axes[0].legend(fontsize=7)
    figure.suptitle("jackknife_whirl: every method at comparable cost (sampled every 1 s)")
    figure.tight_layout()
    out = os.path.join(out_dir, "long_run.png")
    figure.savefig(out, dpi=DPI)
    plt.close(figure)
    return out


def plot_paper(out_dir):
    path = os.path.join(out_dir, "paper_relative_error.csv")
    if not os.path.exists(path):
        return None
    rows = read_rows(path)
    figure, axes = plt.subplots(1, 2, figsize=(10, 4))
    styles = {("birkhoff2", "paper"): ("tab:blue", "-"), ("birkhoff2", "autonomous"): ("tab:cyan", ":"),
              ("rk2", "paper"): ("tab:orange", "-"), ("birkhoff4", "paper"): ("tab:green", "-"),
              ("rk4", "paper"): ("tab:red", "-")}
    titles = {"paper": "paper window (pi/2, pi - 0.05)", "wide": "(0.05, pi - 0.05): pi1 = 0 at t = 0.7196"}
    for axis, window in zip(axes, ("paper", "wide")):
        for (method, form), (colour, style) in styles.items():
            data = [r for r in rows if r["window"] == window and r["method"] == method and r["form"] == form]
            if not data:
                continue
            axis.semilogy([number(r["t"]) for r in data], positive([number(r["relative_error"]) for r in data]),
                          color=colour, linestyle=style, label=f"{method} ({form} form)", linewidth=1)
        axis.set_title(titles[window], fontsize=10)
        axis.set_xlabel("t [s]")
        axis.set_ylabel("|pi1 - pi1_exact| / |pi1_exact|")
        axis.grid(True, alpha=0.4)
    axes[0].legend(fontsize=7)
    figure.suptitle("paper figs. 1-2: relative error of pi1, tau = 0.001, start pi1 = 1 at t = pi/2")
    figure.tight_layout()
    out = os.path.join(out_dir, "paper_figures.png")
    figure.savefig(out, dpi=DPI)
    plt.close(figure)
    return out


def cheapest(runs, column, threshold):
    """The measured run with the smallest wall time whose `column` is <= threshold (None if none)."""
    good = [r for r in runs if number(r[column]) <= threshold]
    return min(good, key=lambda r: number(r["wall_median_s"])) if good else None


def setting(r):
    return f"h={number(r['step_size_s']):.4g}" if r["method"] not in ("dopri5", "odeint_dopri5") \
        else f"tol={r['tolerance']}"


def markdown(rows, checks, out_dir, plots):
    lines = ["# Work-precision results", "",
             "Generated by `bench/bench_plot.py` from `work_precision.csv` (written by `work_precision`).",
             "Wall times are medians of the repetitions after a warm-up run, on a shared 2-core machine:",
             "compare methods within one run (ratios), not across runs.", ""]
    lines += ["## References", "", "| scene | reference | estimated reference error: position [m] | heading [rad] |",
              "|---|---|---|---|"]
    for c in checks:
        lines.append(f"| {c['scene']} | {c['reference']} | {c['position_difference_m']} | "
                     f"{c['heading_difference_rad']} |")
    lines.append("")
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    lines += ["## Cost to reach an accuracy", "",
              "Cheapest measured run (step sizes halve, so each entry is within a factor ~2 of the optimum)",
              "reaching the accuracy; `-` = no run in the sweep reached it.", ""]
    header = "| scene | method | " + " | ".join(f"pos <= {t:g} m" for t in POSITION_TARGETS) + \
        f" | energy <= {ENERGY_TARGET:g} J |"
    lines += [header, "|---|---|" + "---|" * (len(POSITION_TARGETS) + 1)]
    for scene in scenes:
        runs = [r for r in ok_rows(rows) if r["scene"] == scene]
        for method in METHOD_ORDER:
            mine = [r for r in runs if r["method"] == method]
            if not mine:
                continue
            cells = []
            for column, threshold in [("position_error_m", t) for t in POSITION_TARGETS] + \
                    [("max_energy_residual_J", ENERGY_TARGET)]:
                best = cheapest(mine, column, threshold)
                cells.append(f"{number(best['wall_median_s']):.3g} s ({setting(best)})" if best else "-")
            lines.append(f"| {scene} | {method} | " + " | ".join(cells) + " |")
    lines.append("")
    lines += ["## Our steppers against Boost.Odeint on the same right-hand side", "",
              "Ratio of median wall times, ours / odeint, at the same step size (rk4) or tolerance (dopri5);",
              "median over the sweep, with range. (Our dopri5 restarts odeint's stepper every simulator step",
              "of 0.1 s; odeint's integrate_adaptive keeps one stepper, so the rhs counts differ too.)", "",
              "| scene | rk4 / odeint_rk4 | dopri5 / odeint_dopri5 | rhs evaluations dopri5 / odeint_dopri5 |",
              "|---|---|---|---|"]
    for scene in scenes:
        runs = {(r["method"], r["step_size_s"], r["tolerance"]): r for r in ok_rows(rows) if r["scene"] == scene}
        cells = []
        for ours, theirs, column in (("rk4", "odeint_rk4", "wall_median_s"),
                                     ("dopri5", "odeint_dopri5", "wall_median_s"),
                                     ("dopri5", "odeint_dopri5", "rhs_evaluations")):
            ratios = sorted(number(r[column]) / number(runs[(theirs, k[1], k[2])][column])
                            for k, r in runs.items() if k[0] == ours and (theirs, k[1], k[2]) in runs
                            and number(runs[(theirs, k[1], k[2])][column]) > 0)
            if ratios:
                mid = ratios[len(ratios) // 2] if len(ratios) % 2 else 0.5 * (ratios[len(ratios) // 2 - 1] +
                                                                             ratios[len(ratios) // 2])
                cells.append(f"{mid:.2f} ({ratios[0]:.2f}-{ratios[-1]:.2f})")
            else:
                cells.append("-")
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
    lines.append("")
    lines += ["## Plots", ""] + [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in plots if p] + [""]
    lines += ["## Every run", "",
              "| scene | method | h [s] / tol | steps | rhs evals | Newton its | wall [s] | cpu [s] | pos err [m] | "
              "heading err [rad] | max energy res [J] | max p2 res [kg m^2/s] | status |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['method']} | {setting(r)} | {r['steps']} | {r['rhs_evaluations']} | "
                     f"{r['newton_iterations']} | {number(r['wall_median_s']):.3g} | {number(r['cpu_median_s']):.3g} | "
                     f"{number(r['position_error_m']):.2e} | {number(r['heading_error_rad']):.2e} | "
                     f"{number(r['max_energy_residual_J']):.2e} | {number(r['max_p2_residual']):.2e} | {r['status']} |")
    lines.append("")
    with open(os.path.join(out_dir, "work_precision.md"), "w") as handle:
        handle.write("\n".join(lines))


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
    rows = read_rows(os.path.join(out_dir, "work_precision.csv"))
    checks = read_rows(os.path.join(out_dir, "reference_check.csv"))
    plots = [plot_work_precision(rows, checks, scene, out_dir) for scene in dict.fromkeys(r["scene"] for r in rows)]
    plots.append(plot_long_run(out_dir))
    plots.append(plot_paper(out_dir))
    markdown(rows, checks, out_dir, plots)
    for p in plots:
        if p:
            print(f"wrote {p} ({os.path.getsize(p) // 1024} kB)")
    print(f"wrote {os.path.join(out_dir, 'work_precision.md')}")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Plots and Markdown tables from the work_precision CSVs (issues 6 and 11).

    /usr/bin/python3 bench/bench_plot.py [RESULTS_DIR]      (default bench/results)

Reads work_precision.csv, error_vs_time.csv, reference_check.csv, step_cost.csv and
paper_relative_error.csv written by the work_precision executable and writes, beside them:
  work_precision_<scene>.png  final position error [m] and max energy-balance residual [J]
                              against median CPU time [s], log-log, one line per method
  long_run.png                running max energy residual and position error against simulated
                              time on jackknife_whirl 10 000 s, every method at comparable cost
                              (CPU time nearest the cheapest Birkhoffian run reaching 1e-6 m)
  paper_figures.png           relative error of pi1 against the closed form, tau = 0.001 (figs. 1-2)
  work_precision.md           cost-to-accuracy tables, rhs evaluations at equal error, crossover
                              horizons, step cost, the issue 11 goals, the full per-run table
Cost is the process CPU time (median of the repetitions): on a shared machine the wall time
also counts the time the process waited for a core. Wall medians are printed beside it.
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
    "birkhoff2": ("#1f77b4", "o", "-"),
    "birkhoff4": ("#2ca02c", "s", "-"),
    "birkhoff4_suzuki": ("#98df8a", "s", "-"),
    "birkhoff6_kahan_li": ("#17becf", "h", "-"),
    "birkhoff8_kahan_li": ("#9edae5", "h", "-"),
    "birkhoff_gauss4": ("#000080", "p", "-"),
    "birkhoff_gauss6": ("#0000ff", "p", "-"),
    "birkhoff_gauss8": ("#6495ed", "p", "-"),
    "midpoint": ("#7f7f7f", "v", ":"),
    "rk2": ("#ff7f0e", "^", "-"),
    "rk4": ("#d62728", "D", "-"),
    "dopri5": ("#9467bd", "P", "-"),
    "dopri5_sim1s": ("#c5b0d5", "P", "-"),
    "dopri5_sim10s": ("#e377c2", "P", "-"),
    "odeint_rk4": ("#d62728", "x", "--"),
    "odeint_dopri5": ("#9467bd", "*", "--"),
    "odeint_rkf78": ("#8c564b", "*", "--"),
    "odeint_bulirsch_stoer": ("#bcbd22", "*", "--"),
}
METHOD_ORDER = list(METHOD_STYLE)
BIRKHOFFIAN = [m for m in METHOD_ORDER if m.startswith("birkhoff")]
PEERS = ["rk4", "dopri5", "dopri5_sim1s", "dopri5_sim10s", "odeint_rk4", "odeint_dopri5", "odeint_rkf78",
         "odeint_bulirsch_stoer"]
ADAPTIVE = {"dopri5", "dopri5_sim1s", "dopri5_sim10s", "odeint_dopri5", "odeint_rkf78", "odeint_bulirsch_stoer"}
POSITION_TARGETS = (1e-3, 1e-6, 1e-8)  # [m]
ENERGY_TARGETS = (1e-8, 1e-11)  # [J]; 1e-11 J is issue 11's goal on jackknife_whirl (1e-13 of T*0)
COST = "cpu_median_s"


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_rows(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as handle:
        lines = [line for line in handle if not line.startswith("#")]
    return list(csv.DictReader(lines))


def ok_rows(rows):
    return [r for r in rows if r["status"] == "ok"]


def positive(values):
    return [v if (v > 0 and math.isfinite(v)) else math.nan for v in values]


def setting(r):
    if r["method"] in ADAPTIVE:
        return f"tol={number(r['tolerance']):.0e}"
    return f"h={number(r['step_size_s']):.4g}"


def fmt_time(seconds):
    if not math.isfinite(seconds):
        return "-"
    return f"{seconds * 1e3:.3g} ms" if seconds < 0.1 else f"{seconds:.3g} s"


def plot_work_precision(rows, checks, scene, out_dir):
    runs = [r for r in ok_rows(rows) if r["scene"] == scene]
    floors = [number(c["position_difference_m"]) for c in checks if c["scene"] == scene]
    figure, axes = plt.subplots(1, 2, figsize=(12, 5))
    panels = (("position_error_m", "final position error of B [m]"),
              ("max_energy_residual_J", "max |T* - T*0 - W| over the run [J]"))
    for axis, (column, label) in zip(axes, panels):
        for method in METHOD_ORDER:
            mine = sorted((r for r in runs if r["method"] == method), key=lambda r: number(r[COST]))
            if not mine:
                continue
            colour, marker, style = METHOD_STYLE[method]
            axis.loglog([number(r[COST]) for r in mine], positive([number(r[column]) for r in mine]), color=colour,
                        marker=marker, linestyle=style, label=method, markersize=4, linewidth=1.2)
        if column == "position_error_m":
            for target in POSITION_TARGETS[1:]:
                axis.axhline(target, color="black", linewidth=0.6, linestyle=":")
            if floors and math.isfinite(floors[0]) and floors[0] > 0:
                axis.axhline(floors[0], color="grey", linewidth=0.8, linestyle="--")
                axis.annotate("reference vs its check", (0.02, floors[0]), xycoords=("axes fraction", "data"),
                              fontsize=7, color="grey", va="bottom")
        else:
            for target in ENERGY_TARGETS:
                axis.axhline(target, color="black", linewidth=0.6, linestyle=":")
        axis.set_xlabel("median CPU time [s]")
        axis.set_ylabel(label)
        axis.grid(True, which="major", alpha=0.4)
    axes[0].legend(fontsize=6, ncol=2)
    figure.suptitle(f"work-precision: {scene}")
    figure.tight_layout()
    path = os.path.join(out_dir, f"work_precision_{scene}.png")
    figure.savefig(path, dpi=DPI)
    plt.close(figure)
    return path


def curves_by_run(curves):
    """error_vs_time rows grouped per run: {(scene, method, h, tol, sim): [rows in time order]}."""
    runs = defaultdict(list)
    for r in curves:
        runs[(r["scene"], r["method"], r["step_size_s"], r["tolerance"], r["simulator_step_s"])].append(r)
    for key in runs:
        runs[key].sort(key=lambda r: number(r["t"]))
    return runs


def plot_long_run(curves, out_dir):
    """Every method at comparable cost on the longest jackknife run: the run per method whose CPU
    time is nearest (in ratio) that of the cheapest Birkhoffian run reaching 1e-6 m at the end."""
    if not curves:
        return None
    longest = max(curves, key=lambda r: number(r["duration_s"]))["scene"]
    runs = {k: v for k, v in curves_by_run(curves).items() if k[0] == longest}
    reaching = [v for k, v in runs.items() if k[1] in BIRKHOFFIAN and number(v[-1]["position_error_m"]) <= 1e-6]
    if not reaching:
        return None
    anchor = min(reaching, key=lambda v: number(v[0][COST]))
    target = number(anchor[0][COST])
    figure, axes = plt.subplots(1, 2, figsize=(12, 5))
    for method in METHOD_ORDER:
        mine = [v for k, v in runs.items() if k[1] == method]
        if not mine:
            continue
        best = min(mine, key=lambda v: abs(math.log(number(v[0][COST]) / target)))
        colour, marker, style = METHOD_STYLE[method]
        label = f"{method} ({setting(best[0])}, {number(best[0][COST]):.2f} s)"
        t = [number(r["t"]) for r in best]
        axes[0].loglog(t, positive([number(r["max_energy_residual_J"]) for r in best]), color=colour,
                       linestyle=style, marker=marker, markersize=3, label=label, linewidth=1.2)
        axes[1].loglog(t, positive([number(r["position_error_m"]) for r in best]), color=colour, linestyle=style,
                       marker=marker, markersize=3, label=label, linewidth=1.2)
    axes[0].set_ylabel("running max |T* - T*0 - W| [J]")
    axes[1].set_ylabel("position error of B [m]")
    for axis in axes:
        axis.set_xlabel("simulated time [s]")
        axis.grid(True, alpha=0.4)
    axes[0].legend(fontsize=6)
    figure.suptitle(f"{longest}: every method at CPU time nearest {target:.2f} s (the cheapest Birkhoffian "
                    f"run reaching 1e-6 m: {anchor[0]['method']} {setting(anchor[0])})", fontsize=10)
    figure.tight_layout()
    out = os.path.join(out_dir, "long_run.png")
    figure.savefig(out, dpi=DPI)
    plt.close(figure)
    return out


def plot_paper(out_dir):
    rows = read_rows(os.path.join(out_dir, "paper_relative_error.csv"))
    if not rows:
        return None
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


def cheapest(runs, column, threshold, cost=COST):
    """The measured run with the smallest cost whose `column` is <= threshold (None if none)."""
    good = [r for r in runs if number(r[column]) <= threshold]
    return min(good, key=lambda r: number(r[cost])) if good else None


def needed(points, target):
    """Cost needed to reach `target` error: points = [(cost, error)] of one method's sweep. Log-log
    interpolation between the two runs whose errors bracket the target, walking from the cheapest
    run; the cheapest cost if even it is below the target (an upper bound, flagged), inf if none
    reaches it. Returns (cost, flag) with flag '' (interpolated), '<=' (bound) or 'none'."""
    points = sorted((c, e) for c, e in points if c > 0 and math.isfinite(c) and math.isfinite(e))
    if not points:
        return math.inf, "none"
    if points[0][1] <= target:
        return points[0][0], "<="
    for (c0, e0), (c1, e1) in zip(points, points[1:]):
        if e0 > target >= e1:
            if e1 <= 0:
                return c1, ""
            fraction = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(c0) + fraction * math.log(c1 / c0)), ""
    return math.inf, "none"


def crossover_rows(curves):
    """Per jackknife scene with checkpoints, per target and pair (Birkhoffian member, peer): the
    ratio of the CPU time each needs to reach the target at horizon t, for every checkpoint t, and
    the horizon where that ratio crosses 1 (log-linear interpolation between checkpoints)."""
    if not curves:
        return []
    longest = max(curves, key=lambda r: number(r["duration_s"]))["scene"]
    runs = {k: v for k, v in curves_by_run(curves).items() if k[0] == longest}
    times = sorted({number(r["t"]) for v in runs.values() for r in v})
    results = []
    for column, target, unit in [("position_error_m", 1e-6, "m"), ("position_error_m", 1e-8, "m"),
                                 ("max_energy_residual_J", 1e-8, "J"), ("max_energy_residual_J", 1e-11, "J")]:
        rate = {}  # (method, t) -> CPU seconds per simulated second needed
        for method in METHOD_ORDER:
            mine = [v for k, v in runs.items() if k[1] == method]
            for t in times:
                points = []
                for v in mine:
                    at = [r for r in v if number(r["t"]) == t]
                    if at:
                        points.append((number(v[0][COST]) / number(v[0]["duration_s"]), number(at[0][column])))
                if points:
                    rate[(method, t)] = needed(points, target)
        for member in BIRKHOFFIAN:
            for peer in PEERS:
                ratios = []
                for t in times:
                    if (member, t) in rate and (peer, t) in rate:
                        a, b = rate[(member, t)][0], rate[(peer, t)][0]
                        ratios.append((t, a / b if math.isfinite(a) and math.isfinite(b) and b > 0 else
                                       (0.0 if math.isfinite(a) else (math.inf if math.isfinite(b) else math.nan))))
                if not ratios:
                    continue
                crossings = []  # where a finite ratio crosses 1
                for (t0, r0), (t1, r1) in zip(ratios, ratios[1:]):
                    if r0 > 0 and r1 > 0 and math.isfinite(r0) and math.isfinite(r1) and (r0 - 1) * (r1 - 1) < 0:
                        f = math.log(r0) / (math.log(r0) - math.log(r1))
                        crossings.append(math.exp(math.log(t0) + f * math.log(t1 / t0)))

                def reach(method):  # the longest horizon up to which the method reaches the target throughout
                    last = None
                    for t in times:
                        if (method, t) not in rate or not math.isfinite(rate[(method, t)][0]):
                            break
                        last = t
                    return last
                name = "position" if column.startswith("pos") else "energy"
                results.append({"scene": longest, "target": f"{name} <= {target:g} {unit}", "member": member,
                                "peer": peer, "ratios": ratios, "crossings": crossings,
                                "member_reach": reach(member), "peer_reach": reach(peer)})
    return results


def ratio_text(r):
    if r == 0:
        return "only member"
    if math.isinf(r):
        return "only peer"
    if not math.isfinite(r):
        return "neither"
    return f"{r:.2f}"


def markdown(rows, checks, curves, step_costs, out_dir, plots):
    lines = ["# Work-precision results", "",
             "Generated by `bench/bench_plot.py` from the CSVs written by `work_precision`. Costs are medians of",
             "the repetitions (process CPU time; wall time beside it) on a shared 2-core machine: compare methods",
             "within one run, not across runs.", ""]
    lines += ["## References", "",
              "Distance of each scene's reference from its check runs at each checkpoint (`reference_check.csv`).", "",
              "| scene | reference | check | t [s] | position difference [m] | heading difference [rad] | "
              "reference rhs evals / wall | check rhs evals / wall |", "|---|---|---|---|---|---|---|---|"]
    for c in checks:
        t = number(c["t"])
        if t > 0 and abs(math.log10(t) - round(math.log10(t))) > 1e-9 and c is not checks[-1] and \
                any(number(d["t"]) > t for d in checks if d["scene"] == c["scene"]):
            continue  # only decades and each scene's end
        lines.append(f"| {c['scene']} | {c['reference']} | {c['check']} | {c['t']} | {c['position_difference_m']} | "
                     f"{c['heading_difference_rad']} | {c['reference_rhs_evaluations']} / {c['reference_wall_s']} s | "
                     f"{c['check_rhs_evaluations']} / {c['check_wall_s']} s |")
    lines.append("")
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    targets = [("position_error_m", t, "m") for t in POSITION_TARGETS] + \
              [("max_energy_residual_J", t, "J") for t in ENERGY_TARGETS]
    lines += ["## Cost to reach an accuracy", "",
              "Cheapest measured run (by median CPU time; wall median in brackets) reaching the accuracy: final",
              "position error of B, or max energy-balance residual over the run; `-` = no run of the sweep",
              "reached it (the smallest value reached is given). Step sizes halve, so each entry is within",
              "~2x of the optimum.", ""]
    header = "| scene | method | " + " | ".join(
        f"{'pos' if c.startswith('pos') else 'energy'} <= {t:g} {u}" for c, t, u in targets) + " |"
    lines += [header, "|---|---|" + "---|" * len(targets)]
    for scene in scenes:
        runs = [r for r in ok_rows(rows) if r["scene"] == scene]
        for method in METHOD_ORDER:
            mine = [r for r in runs if r["method"] == method]
            if not mine:
                continue
            cells = []
            for column, threshold, _ in targets:
                best = cheapest(mine, column, threshold)
                if best:
                    cells.append(f"{fmt_time(number(best[COST]))} ({fmt_time(number(best['wall_median_s']))}; "
                                 f"{setting(best)})")
                else:
                    floor = min(number(r[column]) for r in mine)
                    cells.append(f"- ({floor:.1e})")
            lines.append(f"| {scene} | {method} | " + " | ".join(cells) + " |")
    lines.append("")
    lines += ["## Best Birkhoffian member against each peer", "",
              "Per scene and accuracy: the cheapest Birkhoffian run reaching it against each peer's cheapest run;",
              "ratio = peer CPU / Birkhoffian CPU (> 1: the Birkhoffian member is faster). Wall-time ratio in brackets.",
              "'> x (not reached ...)': no run of the peer's sweep reached it; its most expensive run already",
              "cost x times the Birkhoffian run (and reached the error given).",
              ""]
    lines += ["| scene | accuracy | best Birkhoffian (CPU, setting) | " + " | ".join(PEERS) + " |",
              "|---|---|---|" + "---|" * len(PEERS)]
    for scene in scenes:
        runs = [r for r in ok_rows(rows) if r["scene"] == scene]
        for column, threshold, unit in targets:
            ours = cheapest([r for r in runs if r["method"] in BIRKHOFFIAN], column, threshold)
            if not ours:
                continue
            cells = []
            for peer in PEERS:
                theirs = cheapest([r for r in runs if r["method"] == peer], column, threshold)
                if not [r for r in runs if r["method"] == peer]:
                    cells.append("")
                elif theirs:
                    cells.append(f"{number(theirs[COST]) / number(ours[COST]):.2f} "
                                 f"({number(theirs['wall_median_s']) / number(ours['wall_median_s']):.2f})")
                else:  # a lower bound: the peer's most expensive run of the sweep did not reach it
                    dearest = max((r for r in runs if r["method"] == peer), key=lambda r: number(r[COST]))
                    cells.append(f"> {number(dearest[COST]) / number(ours[COST]):.2f} (not reached; "
                                 f"{number(dearest[column]):.1e} at {setting(dearest)})")
            name = "pos" if column.startswith("pos") else "energy"
            lines.append(f"| {scene} | {name} <= {threshold:g} {unit} | {ours['method']} "
                         f"({fmt_time(number(ours[COST]))}, {setting(ours)}) | " + " | ".join(cells) + " |")
    lines.append("")
    lines += ["## Right-hand-side evaluations per simulated second at equal final position error", "",
              "rhs evaluations / simulated second needed for a final position error of 1e-6 m and 1e-8 m",
              "(log-log interpolation between the two runs of the sweep that bracket it; `<=` = even the",
              "cheapest run is more accurate, `-` = not reached). Collocation members also evaluate the",
              "passive rates g separately (passive evaluations, cheaper than an rhs evaluation).", ""]
    jack = [s for s in scenes if s.startswith("jackknife")]
    lines += ["| method | " + " | ".join(f"{s}: 1e-6 m | {s}: 1e-8 m" for s in jack) + " |",
              "|---|" + "---|---|" * len(jack)]
    for method in METHOD_ORDER:
        cells = []
        for scene in jack:
            mine = [r for r in ok_rows(rows) if r["scene"] == scene and r["method"] == method]
            for target in (1e-6, 1e-8):
                value, flag = needed([(number(r["rhs_per_simulated_second"]), number(r["position_error_m"]))
                                      for r in mine], target)
                cells.append("-" if flag == "none" else f"{flag}{value:.3g}")
        if any(c != "-" for c in cells) or any(r["method"] == method for r in rows):
            lines.append(f"| {method} | " + " | ".join(cells) + " |")
    lines.append("")
    crossings = crossover_rows(curves)
    if crossings:
        times = [t for t, _ in crossings[0]["ratios"]]
        lines += ["## Crossover horizons", "",
                  f"From the errors at checkpoints of every run of `{crossings[0]['scene']}` (`error_vs_time.csv`):",
                  "for each method and horizon t, the CPU time per simulated second it needs to reach the",
                  "accuracy at t (log-log interpolation over its sweep of the error at t against CPU time per",
                  "simulated second), times t, is the cost of a run of length t. The table gives the ratio",
                  "member / peer of these costs (< 1: the Birkhoffian member is cheaper) at selected horizons,",
                  "the horizons where the ratio crosses 1 (log-linear interpolation between checkpoints), and",
                  "the longest checkpoint up to which each reaches the accuracy at all (with the sweep run).",
                  "'only member' / 'only peer' / 'neither': who reaches the accuracy at that horizon.", ""]
        shown = [t for t in times if t in (10.0, 100.0, 1000.0, 10000.0)]
        lines += ["| accuracy | member | peer | " + " | ".join(f"t = {t:g} s" for t in shown) +
                  " | ratio crosses 1 at | member reaches it up to | peer reaches it up to |",
                  "|---|---|---|" + "---|" * len(shown) + "---|---|---|"]
        for c in crossings:
            ratio_at = dict(c["ratios"])
            if c["member_reach"] is None:
                continue  # the member never reaches the accuracy
            cross = ", ".join(f"{t:.3g} s" for t in c["crossings"]) or "-"
            lines.append(f"| {c['target']} | {c['member']} | {c['peer']} | " +
                         " | ".join(ratio_text(ratio_at.get(t, math.nan)) for t in shown) +
                         f" | {cross} | {c['member_reach']:g} s | " +
                         (f"{c['peer_reach']:g} s" if c["peer_reach"] is not None else "never") + " |")
        lines.append("")
    if step_costs:
        lines += ["## Cost of one step on the free cart (jackknife_whirl), side by side", "",
                  "Alternating runs of every method (same load), median per-step time over the rounds; ratio to",
                  "rk4 of the CPU medians, and the median of the per-round ratios.", "",
                  "| h [s] | method | CPU per step [us] | wall per step [us] | rhs / step | passive / step | "
                  "iterations / step | CPU ratio to rk4 | median per-round ratio |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for c in step_costs:
            lines.append(f"| {c['step_size_s']} | {c['method']} | {1e6 * number(c['cpu_per_step_s']):.3f} | "
                         f"{1e6 * number(c['wall_per_step_s']):.3f} | {c['rhs_per_step']} | {c['passive_per_step']} | "
                         f"{c['iterations_per_step']} | {number(c['cpu_ratio_to_first']):.3f} | "
                         f"{number(c['median_round_cpu_ratio_to_first']):.3f} |")
        lines.append("")
    lines += ["## Plots", ""] + [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in plots if p] + [""]
    lines += ["## Every run", "",
              "| scene | method | setting | steps | rhs evals | passive evals | iterations / step | rhs / sim. s | "
              "reps | CPU | wall | pos err [m] | heading err [rad] | max energy res [J] | max p2 res | status |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['method']} | {setting(r)} | {r['steps']} | {r['rhs_evaluations']} | "
                     f"{r['passive_evaluations']} | {r['iterations_per_step']} | {number(r['rhs_per_simulated_second']):.4g} | "
                     f"{r['repetitions']} | {fmt_time(number(r[COST]))} | {fmt_time(number(r['wall_median_s']))} | "
                     f"{number(r['position_error_m']):.2e} | {number(r['heading_error_rad']):.2e} | "
                     f"{number(r['max_energy_residual_J']):.2e} | {number(r['max_p2_residual']):.2e} | {r['status']} |")
    lines.append("")
    with open(os.path.join(out_dir, "work_precision.md"), "w") as handle:
        handle.write("\n".join(lines))


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
    rows = read_rows(os.path.join(out_dir, "work_precision.csv"))
    checks = read_rows(os.path.join(out_dir, "reference_check.csv"))
    curves = read_rows(os.path.join(out_dir, "error_vs_time.csv"))
    step_costs = read_rows(os.path.join(out_dir, "step_cost.csv"))
    finals = [c for c in checks if number(c["t"]) == max(number(d["t"]) for d in checks if d["scene"] == c["scene"])]
    plots = [plot_work_precision(rows, finals, scene, out_dir) for scene in dict.fromkeys(r["scene"] for r in rows)]
    plots.append(plot_long_run(curves, out_dir))
    plots.append(plot_paper(out_dir))
    markdown(rows, checks, curves, step_costs, out_dir, plots)
    for p in plots:
        if p:
            print(f"wrote {p} ({os.path.getsize(p) // 1024} kB)")
    print(f"wrote {os.path.join(out_dir, 'work_precision.md')}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Plots reversible_whirl's trace (src/apps/reversible_whirl.cpp): energy residual and step size
against time on jackknife_whirl, fixed step against the reversible adaptive step of about the same
final error. usage: /usr/bin/python3 bench/plot_reversible_whirl.py TRACE.csv OUT.png"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    trace_path, out_path = sys.argv[1], sys.argv[2]
    with open(trace_path) as handle:
        title = handle.readline().lstrip("# ").strip()
        rows = list(csv.DictReader(handle))
    t = [float(r["t_s"]) for r in rows]
    figure, (energy, step) = plt.subplots(2, 1, figsize=(9, 7))
    energy.loglog(t, [float(r["fixed_energy_residual_J"]) for r in rows], lw=0.6, label="fixed step")
    energy.loglog(t, [float(r["reversible_energy_residual_J"]) for r in rows], lw=0.6, label="reversible adaptive")
    energy.set_xlabel("t [s]")
    energy.set_ylabel("|T* − T*₀| [J] (sampled each second)")
    energy.set_title("jackknife_whirl: " + title, fontsize=8)
    energy.legend()
    shown = [k for k, value in enumerate(t) if value <= 40.0]
    step.plot([t[k] for k in shown], [float(rows[k]["fixed_step_s"]) for k in shown], drawstyle="steps-pre",
              label="fixed step")
    step.plot([t[k] for k in shown], [float(rows[k]["reversible_mean_step_s"]) for k in shown], drawstyle="steps-pre",
              label="reversible: mean step over each second")
    step.set_xlabel("t [s] (first 40 s)")
    step.set_ylabel("step [s]")
    step.legend()
    figure.tight_layout()
    figure.savefig(out_path, dpi=110)


if __name__ == "__main__":
    main()

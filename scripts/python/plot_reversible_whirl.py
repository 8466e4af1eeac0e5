#!/usr/bin/python3
"""plot_reversible_whirl: docs/reversible_whirl.png from reversible_whirl's trace (docs/accuracy.md §4.2).

    /usr/bin/python3 scripts/python/plot_reversible_whirl.py [TRACE.csv] [-o OUT.png]
    (defaults: bench/results/reversible_whirl_trace.csv, docs/reversible_whirl.png)

Two panels against scene time t [s]: the energy residual |T* - T*0| [J] each second (log) of the
fixed step, the reversible control and the adaptive control that reach about the same final error;
and their mean step over each second [s]. Draws with matplotlib (Agg: no display needed).
Exit codes: 0 written; 2 a missing or malformed trace.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

SERIES = (("fixed", "fixed step", "tab:gray"), ("reversible", "reversible control", "tab:blue"),
          ("adaptive", "adaptive control", "tab:red"))


def read_trace(path):
    """(the trace's first comment line, {column: [float]})."""
    with open(path) as f:
        title = f.readline().lstrip("# ").strip()
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError("%s has no rows" % path)
    return title, {name: [float(row[name]) for row in rows] for name in rows[0]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trace", nargs="?", default="bench/results/reversible_whirl_trace.csv")
    parser.add_argument("-o", "--output", default="docs/reversible_whirl.png")
    args = parser.parse_args(argv)
    try:
        title, columns = read_trace(args.trace)
        time = columns["t_s"]
    except (OSError, ValueError, KeyError) as error:
        print("plot_reversible_whirl: %s: %s" % (args.trace, error), file=sys.stderr)
        return 2
    figure, (energy, step) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    for key, label, colour in SERIES:
        residual = columns.get(key + "_energy_residual_J")
        if residual is None or all(value != value for value in residual):  # NaN: no such run
            continue
        energy.semilogy(time, [max(value, 1e-16) for value in residual], color=colour, lw=0.6, label=label)
        step.plot(time, columns[key + ("_step_s" if key == "fixed" else "_mean_step_s")], color=colour, lw=0.6,
                  label=label)
    energy.set_ylabel("|T* - T*0| each second [J]")
    energy.legend(loc="upper left", fontsize=8)
    energy.set_title(title.replace(": ", ":\n", 1), fontsize=8)
    step.set_ylabel("mean step over the second [s]")
    step.set_xlabel("t [s]")
    figure.tight_layout()
    figure.savefig(args.output, dpi=110)
    print("plot_reversible_whirl: wrote %s" % args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Randomized cart_simulate sweep (issue 17): every input either runs or is refused by name.

Runs cart_simulate RUNS times over random shipped scenes, start times (0 ... 1e6 s), durations
(1e-3 ... 30 s, about half of them within 1e-9 (relative) of a whole number of steps), step sizes,
output rates (mostly whole multiples of the step, some not), integrators, dopri5 tolerances (some
below the floor) and Birkhoffian forms. Each run must end in one of:
  exit 0   with a CSV whose rows are finite, strictly increasing in time, first at t0 and last at
           t0 + T (to 1e-9 h + 4 ulp: grid rows are written at t0 + k/HZ);
  exit 2/3/4/5  with a last stderr line "cart_simulate: ..." naming the problem (4 keeps the rows
           written so far, which must still parse; 5, the accuracy guard at ERROR, writes them all);
and never an abort, a crash, another exit status or a run past the time budget (BUDGET s).
Prints the counts per outcome and per refusal reason, and "N passed, N failed"; exits 1 on a failure.

Usage: checks/cli_sweep.py [--runs 2000] [--seed 17] [--jobs 2] [--budget 120]
                            [--binary .ws/devel/lib/birkhoff_cart/cart_simulate]
"""
import argparse
import collections
import concurrent.futures
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE_DIR = os.path.join(REPO, "config", "scenes")
# Every registry member (cart_simulate --help), the default scene's birkhoff_gauss4 included.
INTEGRATORS = ["birkhoff2", "birkhoff4", "birkhoff_gauss4", "birkhoff_gauss6", "birkhoff_gauss8", "birkhoff4_suzuki",
               "birkhoff6_kahan_li", "birkhoff8_kahan_li", "rk2", "rk4", "dopri5", "midpoint"]
STEPS = [1e-4, 2e-4, 2.5e-4, 5e-4, 1e-3, 2e-3, 2.5e-3, 5e-3, 1e-2, 2e-2]  # h [s]
TIME_LINE = re.compile(r"^(  time:\s*)(\S+)(.*)$", re.M)


def ulp(x):
    return math.ulp(abs(x))


def choose(rng, scenes):
    """One random run: the scene and the command-line options (as text)."""
    scene = rng.choice(scenes)
    kind = rng.random()
    if kind < 0.1:
        start = 0.0
    elif kind < 0.2:
        start = float(rng.choice([1.0, 1000.0, 1e5, 1e6]))
    else:
        start = 10.0 ** rng.uniform(-3.0, 6.0)  # 1 ms ... 1e6 s
    h = rng.choice(STEPS)
    duration = 10.0 ** rng.uniform(-3.0, math.log10(30.0))  # 1 ms ... 30 s
    if rng.random() < 0.5:  # within 1e-9 (relative) of a whole number of steps, either side
        n = max(1, round(duration / h))
        duration = n * h * (1.0 + rng.uniform(-1e-9, 1e-9))
    options = ["--step", repr(h), "--duration", repr(duration)]
    if rng.random() < 0.9:
        rate = 1.0 / (rng.choice([1, 1, 2, 5, 10, 20, 50, 100]) * h)  # a whole multiple of h
    else:
        rate = 10.0 ** rng.uniform(-1.0, 4.0)  # usually not: a refusal by name
    options += ["--output-rate", repr(rate)]
    integrator = rng.choice(INTEGRATORS)
    options += ["--integrator", integrator]
    if integrator == "dopri5" or rng.random() < 0.1:
        options += ["--tolerance", repr(10.0 ** rng.uniform(-17.0, -4.0))]
    if rng.random() < 0.2:
        options += ["--birkhoffian-form", rng.choice(["autonomous", "paper"])]
    return scene, start, duration, h, options


def check_csv(path, start, end, h, complete):
    """None if the CSV is sound, else what is wrong with it."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as error:
        return "no CSV: %s" % error
    if not lines or not lines[0].startswith("t,x,y"):
        return "no header"
    times = []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) not in (14, 15):  # 15: local_error_estimate, empty for methods without one
            return "line %d has %d fields" % (number, len(fields))
        try:
            values = [float(v) for v in fields[:14]] + [float(v) for v in fields[14:] if v]
        except ValueError:
            return "line %d does not parse" % number
        if complete and not all(math.isfinite(v) for v in values):
            return "line %d has a non-finite value" % number
        times.append(values[0])
    if not times:
        return "no rows" if complete else None
    if any(b <= a for a, b in zip(times, times[1:])):
        return "row times not strictly increasing"
    if times[0] != start:
        return "first row at %r, not t0 = %r" % (times[0], start)
    if complete and abs(times[-1] - end) > 1e-9 * h + 4.0 * ulp(end):
        return "last row at %r, not t0 + T = %r" % (times[-1], end)
    return None


def one_run(binary, budget, scene, start, duration, h, options, directory, index):
    scene_path = os.path.join(directory, "scene_%d.yaml" % index)
    output = os.path.join(directory, "run_%d.csv" % index)
    with open(scene) as f:
        text = f.read()
    text, replaced = TIME_LINE.subn(lambda m: m.group(1) + repr(start) + m.group(3), text, count=1)
    if replaced != 1:
        return ("fail", "scene %s has no initial_state time line" % scene, "")
    with open(scene_path, "w") as f:
        f.write(text)
    command = [binary, "--quiet", "--scene", scene_path, "--output", output] + options
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=budget)
    except subprocess.TimeoutExpired:
        return ("fail", "past the %g s budget" % budget, " ".join(command))
    finally:
        os.remove(scene_path)
    stderr = result.stderr.strip()
    outcome = None
    end = start + duration
    if result.returncode == 0:
        problem = check_csv(output, start, end, h, complete=True)
        outcome = ("exit 0", None) if problem is None else ("fail", "exit 0 but " + problem)
    elif result.returncode in (2, 3, 4, 5):
        first = stderr.splitlines()[-1] if stderr else ""  # the reason: the last line (a drift warning may precede it)
        if not first.startswith("cart_simulate: ") or "unexpected error" in first:
            outcome = ("fail", "exit %d without a named reason: %r" % (result.returncode, first[:200]))
        else:
            # 4 keeps the rows so far; 5 (accuracy guard at ERROR) wrote them all
            problem = check_csv(output, start, end, h, complete=result.returncode == 5) if result.returncode in (4, 5) else None
            outcome = (("exit %d" % result.returncode), reason_of(first)) if problem is None else (
                "fail", "exit 4 with a broken CSV: " + problem)
    else:
        outcome = ("fail", "exit %d: %s" % (result.returncode, stderr[-300:]))
    if os.path.exists(output):
        os.remove(output)
    return outcome + (" ".join(command),)


def reason_of(line):
    """A short class of a refusal message, for the counts."""
    for pattern, name in [
        (r"too far from 0", "time resolution (t + h would round)"),
        (r"not a whole number of steps", "output interval not whole steps"),
        (r"dopri5 tolerance must be", "dopri5 tolerance below the floor"),
        (r"shorter than .* of the step", "duration shorter than 1e-5 h"),
        (r"must not exceed the duration", "step longer than the duration"),
        (r"internal steps", "dopri5 work limit"),
        (r"step failed", "step failed (StepError)"),
        (r"paper_analytic", "paper_analytic reference off its solution (moved t0)"),
        (r"^cart_simulate: accuracy", "accuracy guard reached ERROR"),
    ]:
        if re.search(pattern, line):
            return name
    return re.sub(r"[-+]?\d[\d.]*(e[-+]?\d+)?", "#", line[15:90])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--budget", type=float, default=120.0, help="seconds one run may take")
    parser.add_argument("--binary", default=os.path.join(REPO, ".ws", "devel", "lib", "birkhoff_cart", "cart_simulate"))
    args = parser.parse_args()
    if not (1 <= args.runs <= 10**6 and 1 <= args.jobs <= 64 and 0 < args.budget <= 3600):
        parser.error("--runs 1..1e6, --jobs 1..64, --budget in (0, 3600] s")
    if not os.access(args.binary, os.X_OK):
        parser.error("no executable cart_simulate at %s (build the workspace first)" % args.binary)
    scenes = sorted(os.path.join(SCENE_DIR, f) for f in os.listdir(SCENE_DIR) if f.endswith(".yaml"))
    rng = random.Random(args.seed)
    plans = [choose(rng, scenes) for _ in range(args.runs)]
    started = time.monotonic()
    counts = collections.Counter()
    reasons = collections.Counter()
    failures = []
    with tempfile.TemporaryDirectory(prefix="cli_sweep_") as directory, \
            concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(one_run, args.binary, args.budget, *plan, directory, i) for i, plan in enumerate(plans)]
        for done, future in enumerate(concurrent.futures.as_completed(futures), start=1):
            kind, reason, command = future.result()
            counts[kind] += 1
            if kind == "fail":
                failures.append((reason, command))
                print("cli_sweep: FAIL %s\n    %s" % (reason, command), flush=True)
            elif reason:
                reasons[(kind, reason)] += 1
            if done % 250 == 0:
                print("cli_sweep: %d of %d runs done" % (done, args.runs), file=sys.stderr, flush=True)
    print("cli_sweep: %d runs (seed %d, %d jobs) in %.0f s: %s" % (
        args.runs, args.seed, args.jobs, time.monotonic() - started,
        ", ".join("%s: %d" % kv for kv in sorted(counts.items()))))
    for (kind, reason), count in sorted(reasons.items()):
        print("  %-7s %5d  %s" % (kind, count, reason))
    print("%d passed, %d failed" % (args.runs - len(failures), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

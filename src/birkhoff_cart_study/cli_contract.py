"""The batch CLI's contract, and the seeded random runs that probe it (study files with
`random_runs`): every input either runs or is refused by name (docs/hard_cases.md §11).

A run must end in one of:
  exit 0        with a CSV whose rows are finite, strictly increasing in time, first at t0 and
                last at t0 + T (to 1e-9 h + 4 ulp: grid rows are written at t0 + k/HZ);
  exit 2/3/4/5  with a last stderr line "cart_simulate: ..." naming the problem (4 keeps the rows
                written so far, which must still parse; 5, the accuracy guard at ERROR, writes them all);
and never an abort, a crash, another exit status or a run past the task's time limit."""
import math
import random
import re

STEPS = [1e-4, 2e-4, 2.5e-4, 5e-4, 1e-3, 2e-3, 2.5e-3, 5e-3, 1e-2, 2e-2]  # h [s]
TIME_LINE = re.compile(r"^(  time:\s*)(\S+)(.*)$", re.M)


def random_runs(seed, count, scene_names, integrators, adaptive, forms):
    """`count` random runs (seeded): each a dict with the scene's name, the start time t0 [s], the
    duration T [s], the step h [s] and the other cart_simulate options. `adaptive`: the integrators
    that read a tolerance (each of their runs gets one); `forms`: the Birkhoffian forms."""
    rng = random.Random(seed)
    runs = []
    for _ in range(count):
        scene = rng.choice(scene_names)
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
        run = {"scene": scene, "start_time": start, "duration": duration, "step": h}
        if rng.random() < 0.9:
            run["output_rate"] = 1.0 / (rng.choice([1, 1, 2, 5, 10, 20, 50, 100]) * h)  # a whole multiple of h
        else:
            run["output_rate"] = 10.0 ** rng.uniform(-1.0, 4.0)  # usually not: a refusal by name
        run["method"] = rng.choice(integrators)
        if run["method"] in adaptive or rng.random() < 0.1:
            run["tolerance"] = 10.0 ** rng.uniform(-17.0, -4.0)
        if rng.random() < 0.2:
            run["birkhoffian_form"] = rng.choice(forms)
        runs.append(run)
    return runs


def with_start_time(scene_text, start):
    """The scene's text with initial_state.time set to `start` [s] (None if it has no such line)."""
    text, replaced = TIME_LINE.subn(lambda m: m.group(1) + repr(start) + m.group(3), scene_text, count=1)
    return text if replaced == 1 else None


# Columns that may be empty in a row (the header names every column: the odometry sensor and the
# actuators add theirs): the last step's error estimate of an integrator without one.
OPTIONAL_COLUMNS = {"local_error_estimate"}


def check_csv(path, start, end, h, complete):
    """None if the CSV keeps the contract, else what is wrong with it. Every row has the header's
    columns (the scene's own list: cart_simulate adds the sensor's and the actuators' columns)."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as error:
        return "no CSV: %s" % (getattr(error, "strerror", None) or error)
    if not lines or not lines[0].startswith("t,x,y"):
        return "no header"
    header = lines[0].split(",")
    optional = {i for i, name in enumerate(header) if name in OPTIONAL_COLUMNS}
    times = []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != len(header):
            return "line %d has %d fields, the header %d" % (number, len(fields), len(header))
        try:
            values = [float(v) for i, v in enumerate(fields) if v or i not in optional]
        except ValueError:
            return "line %d does not parse" % number
        if complete and not all(math.isfinite(v) for v in values):
            return "line %d has a non-finite value" % number
        times.append(values[0])
    if not times:
        return "no rows" if complete else None
    if any(b <= a for a, b in zip(times, times[1:])):
        return "row times not strictly increasing"
    if start is not None and times[0] != start:
        return "first row at %r, not t0 = %r" % (times[0], start)
    if complete and end is not None and abs(times[-1] - end) > 1e-9 * h + 4.0 * math.ulp(abs(end)):
        return "last row at %r, not t0 + T = %r" % (times[-1], end)
    return None


def error_line(stderr):
    """The line naming why cart_simulate refused or stopped: the last 'cart_simulate: ' line before
    the usage text (a bad argument is followed by the usage), progress lines aside; a warning such
    as the paper form's drift comes before it."""
    lines = stderr.splitlines()
    usage = next((i for i, line in enumerate(lines) if line.startswith("usage: ")), len(lines))
    named = [line for line in lines[:usage] if line.startswith("cart_simulate: ") and "% of scene time" not in line]
    if named:
        return named[-1]
    return lines[usage - 1] if usage else ""


def reason_of(line):
    """A short class of a refusal message, for the counts."""
    for pattern, name in [
        (r"too far from 0", "time resolution (t + h would round)"),
        (r"not a whole number of steps", "output interval not whole steps"),
        (r"dopri5 tolerance must be", "dopri5 tolerance below the floor"),
        (r"--tolerance is dopri5's local tolerance", "--tolerance with a fixed-step member"),
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


def judge(status, stderr, csv_path, start, duration, h):
    """(outcome, reason) of one run under the contract: outcome "ok" (exit 0, sound CSV),
    "refused" (exit 2–5 with a named reason and a sound partial CSV) or "failed"."""
    end = start + duration if start is not None and duration is not None else None
    last = error_line(stderr)
    if status == 0:
        problem = check_csv(csv_path, start, end, h, complete=True)
        return ("ok", None) if problem is None else ("failed", "exit 0 but " + problem)
    if status in (2, 3, 4, 5):
        if not last.startswith("cart_simulate: ") or "unexpected error" in last:
            return "failed", "exit %d without a named reason: %s" % (status, last[:200])
        problem = check_csv(csv_path, start, end, h, complete=status == 5) if status in (4, 5) else None
        if problem is not None:
            return "failed", "exit %d with a broken CSV: %s" % (status, problem)
        return "refused", "exit %d: %s" % (status, reason_of(last))
    return "failed", "exit %d: %s" % (status, stderr.strip()[-300:])

"""A reference judges only what it resolves (docs/studies.md, "References"): it is accepted for a
goal only when two independent settings or methods of it agree to a tenth of that goal. A goal it
cannot resolve gets no verdict and no ratio ("unresolved") in every table and plot; the summary
line names it and the study exits with status 3.

Each reference of a work_precision study runs twice — the reference and its check (long double
rkf78 against long double bulirsch_stoer; dopri5 at 1e-13 against 1e-12) — and their distance at
every checkpoint is their spread; a cli_runs reference is a member at a step and at half of it."""
import math

RESOLUTION = 10.0  # a goal g is resolved where the reference and its check differ by at most g / RESOLUTION


def states(text):
    """{t: (x, y)} of a reference file (work_precision --reference-run's CSV)."""
    rows = {}
    for line in text.splitlines():
        if line and not line.startswith(("#", "t,")):
            t, x, y = (float(v) for v in line.split(",")[:3])
            rows[t] = (x, y)
    return rows


def distances(reference_text, check_text):
    """[(t, distance of the hinge B between the two runs [m])] at every checkpoint of both files."""
    a, b = states(reference_text), states(check_text)
    return [(t, math.hypot(a[t][0] - b[t][0], a[t][1] - b[t][1])) for t in sorted(a) if t in b]


def describe_unresolved(what, spread, goal):
    return "%s: the reference and its check differ by %.2g m, more than a tenth of %g m" % (what, spread, goal)


class Resolution:
    """What one reference resolves: its spread (the distance between the reference and its check)
    at each checkpoint, or why there is none (the reference or its check failed)."""

    def __init__(self, name, spreads=None, failure=None, exact=False):
        self.name = name
        self.spreads = spreads or []  # [(t from the start [s], spread [m])]
        self.failure = failure        # why the reference cannot judge at all
        self.exact = exact            # a closed form: resolves every goal

    def spread(self, until):
        """The largest spread over the checkpoints up to `until` [s] (None: nothing to compare)."""
        if self.exact:
            return 0.0
        values = [d for t, d in self.spreads if t <= until * (1 + 1e-12)]
        return max(values) if values else None

    def why_unresolved(self, goal, until, what):
        """None when the reference resolves `goal` [m] up to `until`; else why not (one line)."""
        if self.exact:
            return None
        if self.failure:
            return "%s: reference %s %s" % (what, self.name, self.failure)
        spread = self.spread(until)
        if spread is None:
            return "%s: reference %s has no checkpoint to compare with its check" % (what, self.name)
        if RESOLUTION * spread > goal:
            return describe_unresolved("%s (reference %s)" % (what, self.name), spread, goal)
        return None

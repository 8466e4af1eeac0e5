"""The race: the best Birkhoffian member against each peer, goal by goal and along the accuracy axis.

A work–precision curve here is the CPU time a method (or the Birkhoffian family) needs to reach an
error e: C(e) = the least CPU time of a run whose error is ≤ e. Its measured points are the runs
on its lower envelope (no other run is both cheaper and at least as accurate), so C falls as e
grows. Between two of those points the cost is interpolated linearly in log–log: an estimate of
what a setting landing exactly on e would cost, where the sweep's discrete settings overshoot a
goal. No estimate is made outside the measured range: tighter than the tightest run the method
never got there, looser than the loosest run it would be an extrapolation.

Runs are dicts with "cpu" [s] and the error keys of report.measurements ("error" [m], "energy_rel"
[-], "energy" [J]); nothing here reads files or knows the study.
"""
import math

GOAL_RATIO = 1.2  # the goal: the best Birkhoffian member at least 1.2× cheaper than the peer


def _usable(value):
    return value is not None and not math.isnan(value) and not math.isinf(value) and value >= 0


def envelope(runs, key):
    """The lower envelope of CPU time against runs[key]: [(error, cpu, run)] with error rising and
    cpu strictly falling. An error of exactly 0 stands at the smallest positive double."""
    points = sorted(((max(r[key], math.ulp(0.0)), r["cpu"], r) for r in runs
                     if _usable(r.get(key)) and _usable(r.get("cpu")) and r["cpu"] > 0),
                    key=lambda p: (p[0], p[1]))
    frontier = []
    for error, cpu, run in points:
        if not frontier or cpu < frontier[-1][1]:
            frontier.append((error, cpu, run))
    return frontier


def cost_at(frontier, goal):
    """(cost [s] or None, how) of an envelope at exactly `goal`. how: 'measured' (a run on the
    envelope has that error), 'interpolated', 'tighter' (below every run's error: never reached),
    'looser' (above the loosest run's error: it would be extrapolated), 'none' (no runs)."""
    if not frontier:
        return None, "none"
    if goal < frontier[0][0]:
        return None, "tighter"
    if goal > frontier[-1][0]:
        return None, "looser"
    for (e0, c0, _), (e1, c1, _) in zip(frontier, frontier[1:]):
        if e0 < goal < e1:
            s = (math.log(goal) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + s * (math.log(c1) - math.log(c0))), "interpolated"
    return next(c for e, c, _ in frontier if e == goal), "measured"


def _pieces(peer, birkhoffian):
    """The common error range of two envelopes cut where log(peer cost / Birkhoffian cost) changes
    sign: [(from, to, +1 Birkhoffian cheaper | -1 not)], merged, errors rising. [] when the two
    have no error in common."""
    lo, hi = max(peer[0][0], birkhoffian[0][0]), min(peer[-1][0], birkhoffian[-1][0])
    if lo > hi:
        return []
    grid = sorted({lo, hi} | {e for e, _, _ in peer + birkhoffian if lo < e < hi})
    r = [math.log(cost_at(peer, e)[0] / cost_at(birkhoffian, e)[0]) for e in grid]
    if len(grid) == 1:
        return [(lo, hi, 1 if r[0] > 0 else -1)]
    pieces = []
    for (ea, ra), (eb, rb) in zip(zip(grid, r), zip(grid[1:], r[1:])):
        if ra * rb < 0:  # r is linear in log e between two grid points: one root
            crossing = math.exp(math.log(ea) + ra / (ra - rb) * (math.log(eb) - math.log(ea)))
            pieces += [(ea, crossing, 1 if ra > 0 else -1), (crossing, eb, 1 if rb > 0 else -1)]
        else:
            pieces.append((ea, eb, 1 if ra + rb > 0 else -1))
    merged = [pieces[0]]
    for piece in pieces[1:]:
        if piece[2] == merged[-1][2]:
            merged[-1] = (merged[-1][0], piece[1], piece[2])
        else:
            merged.append(piece)
    return merged


def crossovers(peer, birkhoffian):
    """The errors [m] at which the two envelopes cross (rising), inside their common range."""
    return [piece[1] for piece in _pieces(peer, birkhoffian)[:-1]]


def cpu_text(seconds):
    """A CPU time as the report prints it: 3 significant digits, in ms below a second."""
    return "%.3g ms" % (seconds * 1e3) if seconds < 1 else "%.3g s" % seconds


def _m(error):
    return "%.2g m" % error


def describe_crossover(peer, birkhoffian):
    """One phrase: where along the accuracy axis the Birkhoffian envelope is below the peer's."""
    if not peer or not birkhoffian:
        return "—"
    pieces = _pieces(peer, birkhoffian)
    if not pieces:
        return "no error measured by both (peer %s–%s, Birkhoffian %s–%s)" % (
            _m(peer[0][0]), _m(peer[-1][0]), _m(birkhoffian[0][0]), _m(birkhoffian[-1][0]))
    lo, hi = pieces[0][0], pieces[-1][1]
    cheaper = [(a, b) for a, b, sign in pieces if sign > 0]
    if len(cheaper) == len(pieces):
        text = "Birkhoffian cheaper at every measured accuracy (%s–%s)" % (_m(lo), _m(hi))
    elif not cheaper:
        text = "peer cheaper everywhere measured (%s–%s)" % (_m(lo), _m(hi))
    else:
        spans = []
        for a, b in cheaper:
            spans.append("below %s" % _m(b) if a == lo else "above %s" % _m(a) if b == hi
                         else "between %.2g and %s" % (a, _m(b)))
        text = "Birkhoffian cheaper %s" % " and ".join(spans)
    if birkhoffian[0][0] < peer[0][0]:
        text += "; below %s only the Birkhoffian (to %s)" % (_m(peer[0][0]), _m(birkhoffian[0][0]))
    elif peer[0][0] < birkhoffian[0][0]:
        text += "; below %s only the peer (to %s)" % (_m(birkhoffian[0][0]), _m(peer[0][0]))
    return text


def _crossover_cell(peer_runs, birkhoffian_runs, error_floor):
    """The crossover phrase from the runs whose position error the reference resolves (≥ error_floor)."""
    if math.isinf(error_floor):
        return "unresolved"
    def resolved(runs):
        return envelope([r for r in runs if _usable(r.get("error")) and r["error"] >= error_floor], "error")
    text = describe_crossover(resolved(peer_runs), resolved(birkhoffian_runs))
    clipped = any(_usable(r.get("error")) and r["error"] < error_floor for r in peer_runs + birkhoffian_runs)
    return text + ("; errors below %.2g m unresolved" % error_floor if clipped else "")


def _at_goal(peer, birkhoffian, goal):
    """The ratio of the two envelopes' costs at exactly the goal, as a cell's second number."""
    p, p_how = cost_at(peer, goal)
    b, b_how = cost_at(birkhoffian, goal)
    if p is None or b is None:
        return "at the goal: extrapolated" if "looser" in (p_how, b_how) else ""
    return "at the goal %.2f×" % (p / b)


def race(runs, goals, is_birkhoffian, unresolved=None, error_floor=0.0):
    """Markdown: the race table (rows: the best Birkhoffian member, then each peer; columns: the
    goals, then the crossover along the position error) and the summary line.
    goals: [(run key, goal, column title)]; runs carry "method" and "setting" besides their errors.
    unresolved: {goal index: why} of the goals the reference cannot judge: every cell of such a goal
    says "unresolved", with no run, no ratio and no verdict, and the goal is not counted.
    error_floor [m]: the smallest position error the reference resolves; the crossover column is
    drawn from the runs at or above it."""
    unresolved = unresolved or {}
    birkhoffian = [r for r in runs if is_birkhoffian(r["method"])]
    peers = sorted({r["method"] for r in runs if not is_birkhoffian(r["method"])})
    b_curves = {key: envelope(birkhoffian, key) for key, _, _ in goals}
    b_curves.setdefault("error", envelope(birkhoffian, "error"))
    lines = ["| peer | " + " | ".join(title for _, _, title in goals) + " | crossover (position error) |",
             "|---|" + "---|" * (len(goals) + 1)]
    best = []
    for index, (key, goal, _) in enumerate(goals):
        if index in unresolved:
            best.append("unresolved")
            continue
        b_run = _cheapest(b_curves[key], goal)
        if b_run is None:
            best.append("none reaches it")
            continue
        cost, how = cost_at(b_curves[key], goal)
        best.append("%s %s (%s)%s" % (b_run["method"], cpu_text(b_run["cpu"]), b_run["setting"],
                                      "; at the goal %s" % cpu_text(cost) if cost is not None else
                                      "; at the goal: extrapolated" if how == "looser" else ""))
    span = b_curves["error"]
    span_text = "runs from %s to %s" % (_m(span[0][0]), _m(span[-1][0])) if span else "—"
    if math.isinf(error_floor):
        span_text = "unresolved"
    elif span and span[0][0] < error_floor:
        span_text += "; errors below %.2g m unresolved" % error_floor
    lines.append("| *best Birkhoffian* | %s | %s |" % (" | ".join(best), span_text))

    met_cells = cells = 0
    beaten = {goal_index: [] for goal_index in range(len(goals))}  # the peers the goal is missed against
    for p in peers:
        mine = [r for r in runs if r["method"] == p]
        row = []
        for index, (key, goal, _) in enumerate(goals):
            if index in unresolved:
                row.append("unresolved")
                continue
            curve = envelope(mine, key)
            b_run, p_run = _cheapest(b_curves[key], goal), _cheapest(curve, goal)
            if b_run and p_run:
                ratio = p_run["cpu"] / b_run["cpu"]
                met = ratio >= GOAL_RATIO
                at_goal = _at_goal(curve, b_curves[key], goal)
                row.append("%.2f× %s (%s)%s" % (ratio, "met" if met else "missed", cpu_text(p_run["cpu"]),
                                                "; " + at_goal if at_goal else ""))
            elif b_run:
                met, ratio = True, math.inf
                row.append("met: peer never reaches it")
            elif p_run:
                met, ratio = False, 0.0
                row.append("missed: only the peer (%s)" % cpu_text(p_run["cpu"]))
            else:
                row.append("—")
                continue
            cells += 1
            met_cells += met
            if not met:
                beaten[index].append((ratio, p))
        row.append(_crossover_cell(mine, birkhoffian, error_floor))
        lines.append("| `%s` | %s |" % (p, " | ".join(row)))

    verdicts, goals_met, goals_counted, unreached = [], [], 0, []
    for index, (key, goal, title) in enumerate(goals):
        if index in unresolved:
            verdicts.append("unresolved: no verdict")
            continue
        reached_by_b = _cheapest(b_curves[key], goal) is not None
        reached_by_peer = any(_cheapest(envelope([r for r in runs if r["method"] == p], key), goal) for p in peers)
        if not reached_by_b and not reached_by_peer:
            verdicts.append("no method reaches it")
            unreached.append(title)
            continue
        goals_counted += 1
        if not beaten[index]:
            verdicts.append("met")
            goals_met.append(title)
        elif not reached_by_b:
            verdicts.append("missed: no Birkhoffian member reaches it")
        else:
            worst_ratio, worst = min(beaten[index])
            verdicts.append("missed against %d of %d (worst `%s` %.2f×)" % (len(beaten[index]), len(peers), worst, worst_ratio))
    lines.append("| *against every peer* | %s | |" % " | ".join(verdicts))

    summary = ("Goal ratio %g: the best Birkhoffian member is at least %g× cheaper than every peer at %d of %d goals%s, "
               "and in %d of %d peer cells (a cell counts as met when the peer never reaches a goal the "
               "Birkhoffian member reaches)." % (
                   GOAL_RATIO, GOAL_RATIO, len(goals_met), goals_counted,
                   " (%s)" % ", ".join(goals_met) if goals_met else "", met_cells, cells))
    if unreached:
        summary += " No method reaches %s." % ", ".join(unreached)
    if unresolved:
        summary += " No verdict for %s: the reference does not resolve %s." % (
            ", ".join(goals[i][2] for i in sorted(unresolved)), "it" if len(unresolved) == 1 else "them")
    return "\n".join(lines), summary


def _cheapest(frontier, goal):
    """The run of least CPU time reaching the goal: the envelope's point at the largest error ≤ goal."""
    reaching = [run for error, _, run in frontier if error <= goal]
    return reaching[-1] if reaching else None

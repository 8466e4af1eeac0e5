#!/usr/bin/python3
"""rostest study_report: the benchmark report's race of the best Birkhoffian member against each
peer (src/birkhoff_cart_study/race.py, kinds/work_precision_report.py), on synthetic rows whose answers are known.

The work–precision curves are power laws (straight lines in log–log), so interpolation between
measured points is exact and the two curves cross at a known error. Checked: the lower envelope
drops runs that are both dearer and less accurate; the interpolated cost at a goal, and no cost
outside the measured range (tighter: never reached; looser: it would be extrapolated); the
crossover error and its phrase; the verdict against the goal ratio 1.2 cell by cell and per goal;
a method that never reaches a goal; and the page write_report makes from rows in the study's row
format. No master, no processes: plain functions on plain rows."""
import math
import os
import shutil
import sys
import tempfile
import unittest

import rospkg
import rostest

PACKAGE = "birkhoff_cart"
sys.path.insert(0, os.path.join(rospkg.RosPack().get_path(PACKAGE), "src"))

from birkhoff_cart_study import race as race_module  # noqa: E402
from birkhoff_cart_study.race import cost_at, crossovers, describe_crossover, envelope, race  # noqa: E402
from birkhoff_cart_study.kinds.work_precision import RUN_SETTINGS  # noqa: E402
from birkhoff_cart_study.kinds.work_precision_report import GOALS, accuracy_tables, measurements  # noqa: E402
from birkhoff_cart_study.report import write_report  # noqa: E402

RELATIVE = 1e-12  # tolerance of the exact (power-law) interpolations, relative


def peer_cost(error):
    """[s] the synthetic peer: cost ∝ error^-0.2."""
    return 1e-3 * error ** -0.2


def birkhoffian_cost(error):
    """[s] the synthetic Birkhoffian member: cost ∝ error^-0.1, so the two cross at 1e-10 m
    (1e-3 e^-0.2 = 1e-2 e^-0.1 ⇔ e^-0.1 = 10) and the Birkhoffian member is cheaper below it."""
    return 1e-2 * error ** -0.1


CROSSING = 1e-10  # [m]


def run(method, error, cpu, setting="h=1", energy=None, energy_rel=None):
    return {"method": method, "setting": setting, "cpu": cpu, "error": error,
            "energy": energy, "energy_rel": energy_rel}


def is_birkhoffian(method):
    return method.startswith("birkhoff")


# Peer runs at even decades of error, Birkhoffian runs at odd ones: the crossing at 1e-10 m is
# between measured points of both.
PEER = [run("peer", 10.0 ** -k, peer_cost(10.0 ** -k), "tol=1e-%d" % k) for k in range(2, 13, 2)]
BIRKHOFFIAN = [run("birkhoff_a", 10.0 ** -k, birkhoffian_cost(10.0 ** -k), "h=%d" % k) for k in range(3, 14, 2)]


def measure_row(label, method, cpu, error, energy_j, energy_rel, step=None, tolerance=None):
    """A measurement row as the study runner writes it (docs/studies.md, 'The rows')."""
    row = {"type": "measure", "outcome": "ok", "label": label, "method": method, "task_id": "%s-%s-%s" % (method, step, tolerance),
           "analytic": True,  # judged against a closed form: every goal resolved
           "result": {"cpu_median_s": cpu, "wall_median_s": cpu, "position_error_m": error,
                      "max_energy_residual_J": energy_j, "max_energy_residual_rel": energy_rel,
                      "max_p2_residual": 0.0, "rhs_evaluations": 1000, "duration_s": 100.0,
                      "iterations": 0, "steps": 100, "checkpoints": []}}
    if step is not None:
        row["step"] = step
    else:
        row["tolerance"] = tolerance
    return row


class StudyReportTest(unittest.TestCase):
    def setUp(self):
        self.directory = tempfile.mkdtemp(prefix="study_report_test_")

    def tearDown(self):
        shutil.rmtree(self.directory, ignore_errors=True)

    def test_keeps_only_runs_no_other_run_beats_in_both_cost_and_error(self):
        runs = [run("m", 1e-3, 1.0), run("m", 1e-4, 2.0), run("m", 1e-3, 3.0),   # same error, dearer
                run("m", 1e-2, 2.5),                                            # dearer and looser
                run("m", 1e-6, 5.0), run("m", None, 0.1), run("m", float("nan"), 0.1)]
        self.assertEqual([(e, c) for e, c, _ in envelope(runs, "error")], [(1e-6, 5.0), (1e-4, 2.0), (1e-3, 1.0)])

    def test_cost_at_a_goal_is_interpolated_in_log_log_and_none_outside_the_range(self):
        curve = envelope(BIRKHOFFIAN, "error")
        cost, how = cost_at(curve, 1e-6)  # between the runs at 1e-5 and 1e-7
        self.assertEqual(how, "interpolated")
        self.assertAlmostEqual(cost / birkhoffian_cost(1e-6), 1.0, delta=RELATIVE)
        self.assertEqual(cost_at(curve, 1e-5), (birkhoffian_cost(1e-5), "measured"))
        self.assertEqual(cost_at(curve, 1e-14), (None, "tighter"))  # below the tightest run: never reached
        self.assertEqual(cost_at(curve, 1e-2), (None, "looser"))    # above the loosest run: extrapolation
        self.assertEqual(cost_at([], 1e-2), (None, "none"))


    def test_two_power_laws_cross_at_the_known_error(self):
        found = crossovers(envelope(PEER, "error"), envelope(BIRKHOFFIAN, "error"))
        self.assertEqual(len(found), 1)
        self.assertAlmostEqual(math.log10(found[0]), math.log10(CROSSING), delta=1e-9)
        text = describe_crossover(envelope(PEER, "error"), envelope(BIRKHOFFIAN, "error"))
        # Common range 1e-12–1e-3 m; below the peer's tightest run (1e-12 m) only the Birkhoffian member.
        self.assertEqual(text, "Birkhoffian cheaper below 1e-10 m; below 1e-12 m only the Birkhoffian (to 1e-13 m)")

    def test_no_crossing_and_two_crossings(self):
        dear = [dict(r, cpu=r["cpu"] * 1e3) for r in PEER]
        self.assertEqual(crossovers(envelope(dear, "error"), envelope(BIRKHOFFIAN, "error")), [])
        self.assertTrue(describe_crossover(envelope(dear, "error"), envelope(BIRKHOFFIAN, "error")).startswith(
            "Birkhoffian cheaper at every measured accuracy (1e-12 m–0.001 m)"))
        cheap = [dict(r, cpu=r["cpu"] * 1e-3) for r in PEER]
        self.assertTrue(describe_crossover(envelope(cheap, "error"), envelope(BIRKHOFFIAN, "error")).startswith(
            "peer cheaper everywhere measured"))
        # A peer cheaper than the Birkhoffian member from 1e-8 to 1e-6 m and dearer around it (its
        # cost still falls as the error grows, so every run is on its envelope).
        bump = [run("peer", e, birkhoffian_cost(e) * (0.8 if 1e-8 <= e <= 1e-6 else 1.25)) for e in (1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-13)]
        self.assertEqual(len(envelope(bump, "error")), len(bump))
        found = crossovers(envelope(bump, "error"), envelope(BIRKHOFFIAN, "error"))
        self.assertEqual(len(found), 2)
        self.assertTrue(1e-10 < found[0] < 1e-8 and 1e-6 < found[1] < 1e-4, found)
        self.assertIn("Birkhoffian cheaper below %.2g m and above %.2g m" % tuple(found),
                      describe_crossover(envelope(bump, "error"), envelope(BIRKHOFFIAN, "error")))

    def test_curves_without_an_error_in_common(self):
        loose = [r for r in PEER if r["error"] >= 1e-4]
        tight = [r for r in BIRKHOFFIAN if r["error"] <= 1e-7]
        self.assertEqual(crossovers(envelope(loose, "error"), envelope(tight, "error")), [])
        self.assertTrue(describe_crossover(envelope(loose, "error"), envelope(tight, "error")).startswith(
            "no error measured by both"))


    def rows_of(self, text):
        """{row name: its cells} of a markdown table (header and rule skipped)."""
        return {line.split(" | ")[0].strip("| `*"): [c.strip(" |") for c in line.split(" | ")[1:]]
                for line in text.splitlines()[2:]}

    def test_measured_and_interpolated_ratios_and_the_verdict(self):
        goals = [("error", 1e-6, "error ≤ 1e-6 m"), ("error", 1e-11, "error ≤ 1e-11 m"),
                 ("error", 1e-2, "error ≤ 0.01 m"), ("error", 1e-15, "error ≤ 1e-15 m")]
        table, summary = race(PEER + BIRKHOFFIAN, goals, is_birkhoffian)
        cells = self.rows_of(table)
        # 1e-6 m: cheapest runs reaching it are the peer's at 1e-6 m and the member's at 1e-7 m.
        measured = peer_cost(1e-6) / birkhoffian_cost(1e-7)
        at_goal = peer_cost(1e-6) / birkhoffian_cost(1e-6)
        self.assertEqual(cells["peer"][0], "%.2f× missed (%.3g ms); at the goal %.2f×" % (measured, peer_cost(1e-6) * 1e3, at_goal))
        # 1e-11 m: the peer's run at 1e-12 m against the member's at 1e-11 m, past the crossing: met.
        ratio = peer_cost(1e-12) / birkhoffian_cost(1e-11)
        self.assertGreaterEqual(ratio, race_module.GOAL_RATIO)
        self.assertTrue(cells["peer"][1].startswith("%.2f× met" % ratio), cells["peer"][1])
        # 0.01 m lies above the member's loosest run (1e-3 m): no ratio at exactly the goal.
        self.assertTrue(cells["peer"][2].endswith("; at the goal: extrapolated"), cells["peer"][2])
        self.assertIn("; at the goal: extrapolated", cells["best Birkhoffian"][2])
        # 1e-15 m: nobody reaches it.
        self.assertEqual(cells["peer"][3], "—")
        self.assertEqual(cells["best Birkhoffian"][3], "none reaches it")
        self.assertEqual(cells["against every peer"][3], "no method reaches it")
        self.assertTrue(cells["peer"][4].startswith("Birkhoffian cheaper below 1e-10 m"))
        self.assertEqual(cells["against every peer"][:3], ["missed against 1 of 1 (worst `peer` %.2f×)" % measured, "met",
                                                         cells["against every peer"][2]])
        self.assertIn("at 1 of 3 goals (error ≤ 1e-11 m)", summary)
        self.assertIn("No method reaches error ≤ 1e-15 m.", summary)

    def test_a_method_that_never_reaches_a_goal(self):
        goals = [("error", 1e-12, "error ≤ 1e-12 m"), ("energy", 1e-11, "energy ≤ 1e-11 J")]
        peer = [dict(r, energy=1e-12) for r in PEER]                   # every peer run within 1e-11 J
        member = [dict(r, energy=1e-9) for r in BIRKHOFFIAN]           # no member run within it
        loose_peer = [dict(r, method="loose_peer", energy=1e-9) for r in PEER if r["error"] >= 1e-4]
        table, summary = race(peer + member + loose_peer, goals, is_birkhoffian)
        cells = self.rows_of(table)
        self.assertEqual(cells["loose_peer"][0], "met: peer never reaches it")
        self.assertEqual(cells["loose_peer"][1], "—")
        self.assertTrue(cells["peer"][1].startswith("missed: only the peer ("), cells["peer"][1])
        self.assertEqual(cells["best Birkhoffian"][1], "none reaches it")
        self.assertEqual(cells["against every peer"][1], "missed: no Birkhoffian member reaches it")
        # error ≤ 1e-12 m: met against both (the peer's run at 1e-12 m is far dearer than the member's at 1e-13 m).
        self.assertEqual(cells["against every peer"][0], "met")
        self.assertIn("at 1 of 2 goals (error ≤ 1e-12 m), and in 2 of 3 peer cells", summary)

    def test_the_goal_ratio_is_inclusive(self):
        goals = [("error", 1e-6, "error ≤ 1e-6 m")]
        member = [run("birkhoff_a", 1e-6, 1.0)]
        for factor, verdict in ((1.2, "met"), (1.19, "missed")):
            table, _ = race(member + [run("peer", 1e-6, factor)], goals, is_birkhoffian)
            self.assertEqual(self.rows_of(table)["peer"][0].split(" (")[0], "%.2f× %s" % (factor, verdict))


    def test_the_page_from_study_rows_has_the_race_and_its_summary(self):
        rows = [measure_row("whirl", "odeint_rkf78", r["cpu"], r["error"], 1e-12, 1e-14, tolerance=float(r["setting"][4:]))
                for r in PEER]
        rows += [measure_row("whirl", "birkhoff_gauss8", r["cpu"], r["error"], 1e-9, 1e-11, step=0.01 * (1 + i))
                 for i, r in enumerate(BIRKHOFFIAN)]
        runs = measurements(rows, RUN_SETTINGS)
        table, ratios, summary, _ = accuracy_tables(runs, {})
        self.assertIn("| energy ≤ 1e-11 J |", table.splitlines()[0])
        self.assertEqual(table.splitlines()[0].count("|"), len(GOALS) + 2)
        self.assertIn("Birkhoffian cheaper below 1e-10 m", ratios)
        page = os.path.join(self.directory, "results.md")
        unresolved = write_report({"name": "synthetic", "kind": "work_precision"}, rows, page, "study synthetic.yaml",
                                  "synthetic rows")
        self.assertEqual(unresolved, [])
        with open(page) as f:
            text = f.read()
        self.assertIn(ratios, text)
        self.assertIn(summary, text)
        self.assertIn("met: at least 1.2×", text)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "study_report", StudyReportTest)

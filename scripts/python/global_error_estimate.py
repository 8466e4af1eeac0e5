#!/usr/bin/env python3
"""How close is the global error estimate to the error? (docs/accuracy.md §4.5) Runs cart_simulate
with --step-control adaptive --global-error-estimate for every (scene, member, tolerance), reads the
estimate from the summary, compares the final position of the hinge B with the reference of
tolerance_proportionality.py (birkhoff_gauss8 at a fixed step, checked against half that step) and
prints estimate / error per run with the shadow's step pairs and largest h·ρ(J), then, within the
estimate's range (h·ρ(J) <= 3 over >= 8 pairs) and beyond it, the share of runs whose estimate lies
within [1/2, 10] of the error (`?`: the reference does not resolve a tenth of the error).

usage: global_error_estimate.py [--bin-dir DIR] [--jobs N] [--members a,b] [--scenes a,b]
                                [--tolerances 1e-5,1e-7,1e-9] [--rate HZ]
"""
import argparse
import concurrent.futures
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tolerance_proportionality as proportionality  # noqa: E402  (the scenes, the reference runs)

LOW, HIGH = 0.5, 10.0  # the band an estimate is counted in: [LOW, HIGH] x the error [-]


def estimated_run(bin_dir, scene, member, tolerance, rate):
    """tolerance_proportionality's run under the adaptive control with the estimate: its row, with the
    estimate [m], the shadow's pairs, failed steps and largest h·ρ(J), and the summary's verdict."""
    row = proportionality.run(bin_dir, scene, member, "adaptive", tolerance, rate=rate,
                              more=["--global-error-estimate"])
    found = re.search(r"global error estimate (\S+) m .*on (\d+) step pairs, (\d+) failed, "
                      r"largest h\*rho\(J\) ([^:]+): (within|beyond) its range", row.get("summary", ""))
    if row["status"] != 0 or not found:
        row["status"] = row["status"] or -1
        return row
    row["estimate"], row["paired"], row["failed"] = float(found.group(1)), int(found.group(2)), int(found.group(3))
    row["stiffness"], row["in_range"] = float(found.group(4)), found.group(5) == "within"
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bin-dir", default=os.path.join(proportionality.ROOT, ".ws", "devel", "lib", "birkhoff_cart"))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--members", default=",".join(proportionality.MEMBERS))
    parser.add_argument("--scenes", default=",".join(s for s in proportionality.SCENES if s != "noisy_odometry"))
    parser.add_argument("--tolerances", default="1e-5,1e-7,1e-9", help="position tolerances [m]")
    parser.add_argument("--rate", type=float, default=10.0, help="output rate [Hz]")
    args = parser.parse_args()
    scenes, members = args.scenes.split(","), args.members.split(",")
    tolerances = [float(t) for t in args.tolerances.split(",")]

    pool = concurrent.futures.ThreadPoolExecutor(args.jobs)
    references = {}
    for scene in scenes:
        duration = proportionality.duration_of(scene)
        count = max(1, round(duration / proportionality.REFERENCE_STEP.get(scene, 0.002)))
        references[scene] = [pool.submit(proportionality.run, args.bin_dir, scene, "birkhoff_gauss8", "fixed",
                                         step=duration / n, rate=1.0 / duration) for n in (count, 2 * count)]
    jobs = [pool.submit(estimated_run, args.bin_dir, scene, member, tolerance, args.rate)
            for member in members for scene in scenes for tolerance in tolerances]
    rows = [job.result() for job in jobs]
    reference = {}
    for scene, (coarse, fine) in references.items():
        coarse, fine = coarse.result(), fine.result()
        reference[scene] = (fine["x"], fine["y"], math.hypot(coarse["x"] - fine["x"], coarse["y"] - fine["y"]))

    print("estimate / error of the final position of B, rows at %g Hz (reference: birkhoff_gauss8 fixed, h vs h/2)"
          % args.rate)
    for member in members:
        print("\n**%s**\n\n| scene | %s |\n|---|%s" % (member, " | ".join("%g m" % t for t in tolerances),
                                                    "---|" * len(tolerances)))
        for scene in scenes:
            cells = []
            for tolerance in tolerances:
                row = next(r for r in rows if r["member"] == member and r["scene"] == scene and r["tolerance"] == tolerance)
                if row["status"] != 0 or "estimate" not in row:
                    cells.append("exit %d" % row["status"])
                    continue
                x, y, spread = reference[scene]
                row["error"] = math.hypot(row["x"] - x, row["y"] - y)
                row["resolved"] = row["error"] > 0.0 and 10.0 * spread <= row["error"]
                ratio = row["estimate"] / row["error"] if row["error"] > 0.0 else math.inf
                failed = ", %d failed" % row["failed"] if row["failed"] else ""
                cells.append("%.2g%s (%.1e m, %d pairs, hρ %.2g%s)" % (ratio, "" if row["resolved"] else "?", row["error"],
                                                                     row["paired"], row["stiffness"], failed))
            print("| %s | %s |" % (scene, " | ".join(cells)))
    print()
    for member in members:
        judged = [r for r in rows if r["member"] == member and r.get("resolved")]
        for in_range in (True, False):
            mine = [r for r in judged if r["in_range"] == in_range]  # the summary's own verdict
            within = [r for r in mine if LOW * r["error"] <= r["estimate"] <= HIGH * r["error"]]
            ratios = sorted(r["estimate"] / r["error"] for r in mine)
            print("- %s, %s its range: %d of %d judged runs with the estimate within [%g, %g] x the error%s"
                  % (member, "within" if in_range else "beyond", len(within), len(mine), LOW, HIGH,
                     "; estimate / error from %.2g to %.2g" % (ratios[0], ratios[-1]) if ratios else ""))

if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Does the reversible step control meet the tolerance it is given? (issue 12 goal; docs/accuracy.md §4)

For every shipped scene (config/scenes/*.yaml, near_jackknife and reverse_jackknife included) and
tolerances 1e-4 ... 1e-10 m, runs `cart_simulate --step-control reversible --tolerance TOL` over the
scene's duration and compares the final position (x, y) of hinge B with a reference: birkhoff_gauss8
at a fixed step h_ref and at h_ref/2, which must agree to better than 1/10 of the smallest tolerance
judged (else that scene's verdicts at that tolerance are marked "ref?"). Prints, per scene and member,
error/tolerance for each tolerance, the rhs evaluations, and a final count of runs within 10x.

usage: /usr/bin/python3 bench/tolerance_sweep.py [--simulate PATH] [--members birkhoff_gauss4,...]
                                                   [--tolerances 1e-4,...] [--scenes a,b]
"""
import argparse
import csv
import glob
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def run(simulate, scene, out, extra):
    cmd = [simulate, "--scene", scene, "--quiet", "--on-accuracy-error", "warn", "--output", out] + extra
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return None, "over 120 s"

    if done.returncode != 0:
        return None, (done.stderr.strip() or done.stdout.strip()).splitlines()[-1]
    rows = list(csv.DictReader(open(out)))
    rhs = None
    for line in done.stdout.splitlines():
        if "rhs evaluations" in line:
            rhs = int(line.split("rhs evaluations")[0].split(",")[-1].strip().split()[0])
    last = rows[-1]
    return (float(last["t"]), float(last["x"]), float(last["y"]), rhs), None


def scene_duration(path):
    for line in open(path):
        if line.startswith("duration:"):
            return float(line.split(":")[1].split("#")[0])
    raise ValueError(path)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--simulate", default=os.path.join(REPO, ".ws/devel/lib/birkhoff_cart/cart_simulate"))
    parser.add_argument("--members", default="birkhoff_gauss4,birkhoff_gauss8")
    parser.add_argument("--tolerances", default="1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10")
    parser.add_argument("--scenes", default="")
    parser.add_argument("--reference-step", type=float, default=2e-3)
    args = parser.parse_args()
    tolerances = [float(t) for t in args.tolerances.split(",")]
    scenes = sorted(glob.glob(os.path.join(REPO, "config/scenes/*.yaml")))
    if args.scenes:
        scenes = [s for s in scenes if os.path.basename(s)[:-5] in args.scenes.split(",")]
    within = total = 0
    worst = 0.0
    with tempfile.TemporaryDirectory() as scratch:
        out = os.path.join(scratch, "run.csv")
        for scene in scenes:
            name = os.path.basename(scene)[:-5]
            duration = scene_duration(scene)
            single = ["--step", repr(duration), "--output-rate", repr(1.0 / duration)]
            h = args.reference_step
            steps = max(1, round(duration / h))
            h = duration / steps
            ref, err1 = run(args.simulate, scene, out, ["--integrator", "birkhoff_gauss8", "--step", repr(h),
                                                        "--output-rate", repr(1.0 / duration)])
            ref2, err2 = run(args.simulate, scene, out, ["--integrator", "birkhoff_gauss8", "--step", repr(h / 2),
                                                         "--output-rate", repr(1.0 / duration)])
            if ref is None or ref2 is None:
                print(f"{name}: reference failed: {err1 or err2}")
                continue
            ref_spread = math.hypot(ref[1] - ref2[1], ref[2] - ref2[2])
            print(f"\n{name} ({duration:g} s): reference gauss8 h = {h:.3g} s vs h/2 differ by {ref_spread:.2e} m")
            print("  member           " + "".join(f"{t:>11.0e}" for t in tolerances) + "   (error/tolerance; rhs evaluations)")
            for member in args.members.split(","):
                ratios, costs = [], []
                for tol in tolerances:
                    result, failure = run(args.simulate, scene, out, ["--integrator", member, "--step-control", "reversible",
                                                                      "--tolerance", repr(tol)] + single)
                    if result is None:
                        ratios.append("fail")
                        costs.append(failure[:60])
                        continue
                    error = math.hypot(result[1] - ref2[1], result[2] - ref2[2])
                    judged = ref_spread * 10 <= tol
                    ratio = error / tol
                    total += 1
                    if ratio <= 10.0:
                        within += 1
                    worst = max(worst, ratio)
                    ratios.append(f"{ratio:.2g}" + ("" if judged else "?"))
                    costs.append(str(result[3]))
                print(f"  {member:<16} " + "".join(f"{r:>11}" for r in ratios))
                print(f"  {'':<16} " + "".join(f"{c:>11}" for c in costs))
    print(f"\n{within} of {total} runs within 10x of the tolerance; worst error/tolerance {worst:.3g}"
          " ('?': the reference is not 10x tighter than that tolerance)")
    return 0 if within == total else 1


if __name__ == "__main__":
    sys.exit(main())

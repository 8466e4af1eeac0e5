#!/usr/bin/env python3
"""The price of a Python callback (docs/python.md, "Your own Birkhoffian system"): the Chaplygin
sleigh written in Python (simulator.BirkhoffianSystem) against the same sleigh of the C++ core
(simulator.ChaplyginSleigh), integrated by the same member at the same fixed step in the same run,
as process CPU time per right-hand-side evaluation, min of the repetitions. Prints one line per
system and the ratio Python / C++.

usage: bench/python_system_price.py [--member NAME] [--step H] [--duration T] [--repetitions N]
(after `source .ws/devel/setup.bash`)
"""
import argparse
import time

import numpy as np
from birkhoff_cart import simulator

MASS, INERTIA_AT_CENTRE, CENTRE_OFFSET = 2.0, 0.5, 0.3  # [kg], [kg m²], [m]: the C++ sleigh's defaults


def python_sleigh():
    """examples/chaplygin_sleigh.h (S.1)-(S.2), γ = 0: z = (π1, θ, m v, J ω), K = K₀ (the default),
    ∇B = (0, 0, v, ω), Λ = (-(m a ω², -m a v ω), 0, 0)."""
    inertia = INERTIA_AT_CENTRE + MASS * CENTRE_OFFSET ** 2

    def gradient(z, t):
        return (0.0, 0.0, z[2] / MASS, z[3] / inertia)

    def force(z, t):
        v, omega = z[2] / MASS, z[3] / inertia
        return (-MASS * CENTRE_OFFSET * omega ** 2, MASS * CENTRE_OFFSET * v * omega, 0.0, 0.0)

    return simulator.BirkhoffianSystem(4, birkhoffian_gradient=gradient, non_birkhoffian_force=force)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--member", default="birkhoff_gauss8")
    parser.add_argument("--step", type=float, default=0.01, help="h [s]")
    parser.add_argument("--duration", type=float, default=40.0, help="[s]")
    parser.add_argument("--repetitions", type=int, default=3)
    args = parser.parse_args()
    start = np.array([0.0, 0.3, 2.0 * -0.4, (INERTIA_AT_CENTRE + MASS * CENTRE_OFFSET ** 2) * 2.0])
    systems = [("C++ (ChaplyginSleigh)", simulator.ChaplyginSleigh(MASS, INERTIA_AT_CENTRE, CENTRE_OFFSET)),
               ("Python callables", python_sleigh())]
    prices = {}
    print(f"{args.member} at h = {args.step} s over {args.duration} s, min of {args.repetitions} runs (process CPU)")
    for name, system in systems:
        best = float("inf")
        for _ in range(args.repetitions):
            began = time.process_time()
            run = simulator.integrate(system, start, (0.0, args.duration), args.member, step_size=args.step)
            best = min(best, time.process_time() - began)
        prices[name] = best / run.nfev
        print(f"  {name:24s} {best * 1e3:9.2f} ms  {run.nfev:8d} rhs  {prices[name] * 1e9:9.0f} ns/rhs  "
              f"final z {np.array2string(run.y[:, -1], precision=12)}")
    cpp, py = prices[systems[0][0]], prices[systems[1][0]]
    print(f"  Python / C++ per evaluation: {py / cpp:.1f}x")


if __name__ == "__main__":
    main()

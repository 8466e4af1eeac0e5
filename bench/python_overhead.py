#!/usr/bin/env python3
"""What the Python module's crossing costs (docs/python.md, "Cost"): the same run advanced from
Python in batches of steps against the same run in one call (the whole loop in C++), as process CPU
time, min of the repetitions. Prints one line per way of advancing and the ratio of each to C++.

The scene: driven.yaml (birkhoff2 at 1 ms, 60 000 steps, steering and drive torques commanded at every
step from arrays), the cheapest step the package has, so the crossing weighs the most.

usage: bench/python_overhead.py [--scene FILE] [--repetitions N] [--duration T]
(after `source .ws/devel/setup.bash`)
"""
import argparse
import os
import time

import numpy as np
from birkhoff_cart import simulator

HERE = os.path.dirname(os.path.abspath(__file__))


def commands(steps):
    """Steering and drive torques [N·m] for every step: a slow sine and a constant push."""
    k = np.arange(steps)
    return 2.0 * np.sin(2.0 * np.pi * k / 5000.0), np.full(steps, 10.0)


def run_in_batches(scene, batch):
    """The whole run, `batch` steps per call; returns (CPU seconds, final state)."""
    simulation = simulator.Simulation(scene)
    steps = round((simulation.end_time - simulation.time) / simulation.step_size)
    steering, drive = commands(steps)
    start = time.process_time()
    for first in range(0, steps, batch):
        last = min(first + batch, steps)
        simulation.step(last - first, steering_torque=steering[first:last], drive_torque=drive[first:last])
    elapsed = time.process_time() - start
    assert simulation.at_end, "the run did not reach its end"
    return elapsed, simulation.state()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=os.path.join(HERE, "..", "config", "scenes", "driven.yaml"))
    parser.add_argument("--repetitions", type=int, default=5)
    parser.add_argument("--duration", type=float, default=60.0, help="simulated time [s]")
    arguments = parser.parse_args()
    scene = simulator.load_scene(arguments.scene, {"duration": arguments.duration})
    steps = round(scene.duration / scene.step_size)
    ways = [("C++ (one call)", steps), ("Python, 1000 steps a call", 1000), ("Python, 100 steps a call", 100),
            ("Python, 10 steps a call", 10), ("Python, 1 step a call", 1)]
    times = {name: [] for name, _ in ways}
    finals = {}
    for _ in range(arguments.repetitions):  # interleaved, so that a load change hits every way alike
        for name, batch in ways:
            elapsed, final = run_in_batches(scene, batch)
            times[name].append(elapsed)
            finals[name] = final
    reference = min(times[ways[0][0]])
    print(f"scene {scene.name}: {scene.integrator} at h = {scene.step_size:g} s, {steps} steps, torques commanded "
          f"at every step; process CPU time, min of {arguments.repetitions}")
    for name, batch in ways:
        best = min(times[name])
        same = np.array_equal(finals[name], finals[ways[0][0]])
        print(f"  {name:28s} {best * 1e3:9.2f} ms  {best / steps * 1e6:7.3f} us/step  ratio to C++ {best / reference:6.3f}"
              f"  final state {'identical' if same else 'DIFFERS'}")


if __name__ == "__main__":
    main()

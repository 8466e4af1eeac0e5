#!/usr/bin/env python3
"""One cell of the work-precision race from Python (docs/python.md): a member at a nominal step on a
scene, its final hinge position error [m] against a reference file of `work_precision
--reference-run`, as `work_precision --measure` reports it (position_error_m, every digit).

usage: race_cell.py SCENE.yaml REFERENCE.csv METHOD STEP DURATION
"""
import sys

import numpy as np
from birkhoff_cart import simulator

scene_file, reference_file, method = sys.argv[1:4]
nominal_step, duration = float(sys.argv[4]), float(sys.argv[5])
steps = max(1, round(duration / nominal_step))  # as the study: N steps of h = T/N, so the run lasts N·h
step = duration / steps
scene = simulator.load_scene(scene_file, {"duration": steps * step, "reference": None, "integrator": {
    "name": method, "step_size": step, "local_error_estimate": False}})
final = simulator.Simulation(scene).run()
reference = np.atleast_1d(np.genfromtxt(reference_file, delimiter=",", names=True, skip_header=1))[-1]  # at T
x, y = (final[simulator.STATE_FIELDS.index(name)] for name in ("x", "y"))
print(repr(float(np.hypot(x - reference["x"], y - reference["y"]))))

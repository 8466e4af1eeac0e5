#!/usr/bin/env python3
"""A scene's whole run from Python (docs/python.md): prints the accuracy verdict and the final state
as cart_simulate's last CSV row (t,x,y,theta,chi,phi1..phi4,pi1,omega1,omega2,energy,p2 with 17
significant digits), to compare with `cart_simulate --scene SCENE --output F.csv; tail -1 F.csv`.

usage: default_scene.py [SCENE.yaml]   (default: the package's default scene, 60 s)
"""
import pathlib
import sys

from birkhoff_cart import simulator

scene_file = sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "config/scenes/default.yaml"
simulation = simulator.Simulation(simulator.load_scene(scene_file))
final = simulation.run()
diagnostics = simulation.diagnostics()
energy, p2 = (diagnostics[simulator.DIAGNOSTIC_FIELDS.index(name)] for name in ("energy", "p2"))
print("accuracy:", simulation.accuracy()["summary"])
print(",".join("%.17g" % value for value in [*final[:simulator.STATE_FIELDS.index("omega2") + 1], energy, p2]))

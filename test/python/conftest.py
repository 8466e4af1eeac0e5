"""Shared pieces of the study runner's unit tests (plain pytest, no ROS master, no cluster): the
package on the path, a registry like cart_simulate's, the shipped scenes, and a directory of
stand-in executables for the runner's command line (they list the registry and run nothing)."""
import json
import os
import stat
import sys

import pytest

REPOSITORY = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(REPOSITORY, "src"))

from birkhoff_cart_study.registry import parse_listing  # noqa: E402

SCENE_DIR = os.path.join(REPOSITORY, "config", "scenes")

# The shape of `cart_simulate --list-integrators --json`, with the registry's members as it lists them.
LISTING = {
    "integrators": [
        {"name": name, "order": order, "symmetric": symmetric, "reversible": reversible, "vector_stages": False,
         "adaptive": kind in ("Birkhoffian collocation", "composition", "adaptive"),
         "kind": kind, "takes_tolerance": kind == "adaptive", "description": name}
        for name, order, symmetric, reversible, kind in (
            ("birkhoff2", 2, True, True, "Birkhoffian collocation"), ("birkhoff4", 4, True, True, "composition"),
            ("rk2", 2, False, False, "explicit RK"), ("rk4", 4, False, False, "explicit RK"),
            ("dopri5", 5, False, False, "adaptive"), ("midpoint", 2, True, False, "implicit midpoint"),
            ("birkhoff_gauss4", 4, True, True, "Birkhoffian collocation"),
            ("birkhoff_gauss6", 6, True, True, "Birkhoffian collocation"),
            ("birkhoff_gauss8", 8, True, True, "Birkhoffian collocation"),
            ("birkhoff4_suzuki", 4, True, True, "composition"), ("birkhoff6_kahan_li", 6, True, True, "composition"),
            ("birkhoff8_kahan_li", 8, True, True, "composition"))],
    "birkhoffian_forms": ["autonomous", "paper"],
    "step_controls": ["fixed", "reversible", "adaptive"]}


@pytest.fixture
def registry():
    return parse_listing(json.dumps(LISTING))


@pytest.fixture
def study_file(tmp_path):
    """write(text, name="study.yaml") → the path of a study file in a fresh directory."""
    def write(text, name="study.yaml"):
        path = tmp_path / name
        path.write_text(text)
        return str(path)
    return write


@pytest.fixture
def fake_bin_dir(tmp_path):
    """A bin directory whose cart_simulate lists LISTING and whose work_precision fails loudly:
    enough for the runner to read its registry and refuse a study before anything runs."""
    directory = tmp_path / "bin"
    directory.mkdir()
    listing = directory / "listing.json"
    listing.write_text(json.dumps(LISTING))
    scripts = {"cart_simulate": "#!/bin/sh\n[ \"$1\" = --list-integrators ] && exec cat '%s'\necho ran >> '%s'\nexit 99\n"
                                % (listing, directory / "ran"),
               "work_precision": "#!/bin/sh\necho ran >> '%s'\nexit 99\n" % (directory / "ran")}
    for name, text in scripts.items():
        path = directory / name
        path.write_text(text)
        path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(directory)

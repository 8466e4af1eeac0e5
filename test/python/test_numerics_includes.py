"""The core's layers, and the generic numerics that know no system.

The core's headers (include/birkhoff_cart/core/) and sources (src/core/) sit in folders by layer,
lowest first: support (names, version), integrators (the numerics: system concept, step maps, step
controls), examples (systems of the numerics' own, the sleigh), physics (the cart, its effects,
actuators and sensors), cart_binding (the cart as a stepper of any member), scene (what a scene file
says, and its checks), run (a simulation run to its instants, its guard and references) and
node_logic (the node's ROS-free logic). An #include arrow goes to the same folder or a lower layer,
never up; no header sits outside a layer's folder.

And no #include chain from a header of the numerics folder reaches a header of the cart (its model,
effects, state, scene, Birkhoffian form, stepper binding, …): a numerics header may include the
numerics folder, the support folder, the standard library, Eigen and Boost; the walk follows every
"…" include transitively and names the chain that leaves them."""
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
NUMERICS = "include/birkhoff_cart/core/integrators"
SUPPORT = "include/birkhoff_cart/core/support"
# The layers, lowest first: a file may include its own layer's files and lower layers' only.
LAYERS = ["support", "integrators", "examples", "physics", "cart_binding", "scene", "run", "node_logic"]
LAYER_ROOTS = ("include/birkhoff_cart/core", "src/core")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def quoted_includes(root, header):
    """The headers `header` (a path relative to root) includes with "…", as paths relative to root."""
    found = []
    for name in INCLUDE.findall((root / header).read_text(encoding="utf-8")):
        for candidate in (root / "include" / name, (root / header).parent / name):
            if candidate.is_file():
                found.append(candidate.resolve().relative_to(root.resolve()).as_posix())
                break
        else:
            raise AssertionError(f"{header}: cannot resolve #include \"{name}\"")
    return found


def is_generic(path):
    return path.startswith(NUMERICS + "/") or path.startswith(SUPPORT + "/")


def layer_of(path):
    """The layer (index into LAYERS) of a core file, a path relative to the root; None outside the
    core; a ValueError for a core file outside every layer's folder."""
    for base in LAYER_ROOTS:
        if path.startswith(base + "/"):
            folder = path[len(base) + 1:].split("/")[0]
            if folder not in LAYERS:
                raise ValueError(f"{path}: not in a layer's folder ({', '.join(LAYERS)})")
            return LAYERS.index(folder)
    return None


def upward_arrows(root):
    """Every include arrow from a core file to a file of a higher layer, as (file, included) pairs,
    and every core file outside a layer's folder, as (file, None)."""
    bad = []
    for base in LAYER_ROOTS:
        for path in sorted((root / base).rglob("*")):
            if path.suffix not in (".h", ".cpp") or not path.is_file():
                continue
            here = path.relative_to(root).as_posix()
            try:
                rank = layer_of(here)
            except ValueError:
                bad.append((here, None))
                continue
            for included in quoted_includes(root, here):
                try:
                    other = layer_of(included)
                except ValueError:
                    other = None  # named once as a file outside a layer
                if other is not None and other > rank:
                    bad.append((here, included))
    return bad


def system_chains(root, numerics=NUMERICS):
    """Every include chain from a header of `numerics` to a header that is not generic, shortest
    first, as lists of paths; empty when the numerics know no system."""
    bad = []
    for start in sorted((root / numerics).glob("*.h")):
        first = start.relative_to(root).as_posix()
        seen = {first}
        queue = [[first]]
        while queue:
            chain = queue.pop(0)
            for included in quoted_includes(root, chain[-1]):
                if included in seen:
                    continue
                seen.add(included)
                if not is_generic(included):
                    bad.append(chain + [included])
                else:
                    queue.append(chain + [included])
    return bad


def test_no_numerics_header_reaches_a_cart_header():
    chains = system_chains(ROOT)
    assert not chains, "generic numerics headers include system headers:\n" + "\n".join(
        " -> ".join(chain) for chain in chains)


def test_include_arrows_follow_the_layers_downwards():
    bad = upward_arrows(ROOT)
    assert not bad, "core files against the layers:\n" + "\n".join(
        f"{here}: outside a layer's folder" if included is None else f"{here} -> {included} (a higher layer)"
        for here, included in bad)


def test_an_upward_arrow_and_a_file_outside_the_layers_are_named(tmp_path):
    core = tmp_path / "include/birkhoff_cart/core"
    for folder in ("physics", "run"):
        (core / folder).mkdir(parents=True)
    (core / "run/simulation.h").write_text('#include "birkhoff_cart/core/physics/cart_model.h"\n')
    (core / "physics/cart_model.h").write_text('#include "birkhoff_cart/core/run/simulation.h"\n')
    (core / "loose.h").write_text("#pragma once\n")
    (tmp_path / "src/core/physics").mkdir(parents=True)
    (tmp_path / "src/core/physics/cart_model.cpp").write_text('#include "birkhoff_cart/core/run/simulation.h"\n')
    assert upward_arrows(tmp_path) == [
        ("include/birkhoff_cart/core/loose.h", None),
        ("include/birkhoff_cart/core/physics/cart_model.h", "include/birkhoff_cart/core/run/simulation.h"),
        ("src/core/physics/cart_model.cpp", "include/birkhoff_cart/core/run/simulation.h"),
    ]


def test_the_walk_names_a_chain_through_a_generic_header(tmp_path):
    # A numerics header that reaches the cart through another numerics header is named with the chain.
    numerics = tmp_path / NUMERICS
    numerics.mkdir(parents=True)
    physics = tmp_path / "include/birkhoff_cart/core/physics"
    physics.mkdir(parents=True)
    (physics / "cart_model.h").write_text("#pragma once\n")
    (numerics / "diagnostics.h").write_text("#pragma once\n#include <cmath>\n")
    (numerics / "newton.h").write_text('#include "birkhoff_cart/core/integrators/step_error.h"\n')
    (numerics / "step_error.h").write_text(
        '#include "birkhoff_cart/core/integrators/diagnostics.h"\n#include "birkhoff_cart/core/physics/cart_model.h"\n')
    chains = system_chains(tmp_path)
    assert [NUMERICS + "/newton.h", NUMERICS + "/step_error.h", "include/birkhoff_cart/core/physics/cart_model.h"] in chains
    assert [NUMERICS + "/step_error.h", "include/birkhoff_cart/core/physics/cart_model.h"] in chains
    assert len(chains) == 2


def test_an_unresolvable_include_is_refused_by_name(tmp_path):
    numerics = tmp_path / NUMERICS
    numerics.mkdir(parents=True)
    (numerics / "dopri5.h").write_text('#include "nowhere.h"\n')
    with pytest.raises(AssertionError, match='dopri5.h: cannot resolve #include "nowhere.h"'):
        system_chains(tmp_path)

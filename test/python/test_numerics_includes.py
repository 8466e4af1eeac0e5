"""The generic numerics know no system: no #include chain from a header of the numerics folder
(include/birkhoff_cart/core/integrators/) reaches a header of the cart (its model, effects, state,
scene, Birkhoffian form, stepper binding, …). A numerics header may include the numerics folder, the
standard library, Eigen and Boost, and the few generic core headers listed in GENERIC_CORE; the
walk follows every "…" include transitively and names the chain that leaves them."""
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
NUMERICS = "include/birkhoff_cart/core/integrators"
# Core headers that know no cart: the system concept, AD scalars, the work counters, angle
# reduction, the elementary functions with the same bits on every CPU, and the integrator settings
# (plain data: names, step size, tolerances).
GENERIC_CORE = {
    "include/birkhoff_cart/core/deterministic_math.h",
    "include/birkhoff_cart/core/autodiff.h",
    "include/birkhoff_cart/core/birkhoffian_system.h",
    "include/birkhoff_cart/core/diagnostics.h",
    "include/birkhoff_cart/core/angle_reduction.h",
    "include/birkhoff_cart/core/integrator_settings.h",
}
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
    return path.startswith(NUMERICS + "/") or path in GENERIC_CORE


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


def test_the_walk_names_a_chain_through_a_generic_header(tmp_path):
    # A numerics header that reaches the cart through another numerics header is named with the chain.
    numerics = tmp_path / NUMERICS
    numerics.mkdir(parents=True)
    core = tmp_path / "include/birkhoff_cart/core"
    (core / "cart_model.h").write_text("#pragma once\n")
    (core / "diagnostics.h").write_text("#pragma once\n#include <cmath>\n")
    (numerics / "newton.h").write_text('#include "birkhoff_cart/core/integrators/step_error.h"\n')
    (numerics / "step_error.h").write_text(
        '#include "birkhoff_cart/core/diagnostics.h"\n#include "birkhoff_cart/core/cart_model.h"\n')
    chains = system_chains(tmp_path)
    assert [NUMERICS + "/newton.h", NUMERICS + "/step_error.h", "include/birkhoff_cart/core/cart_model.h"] in chains
    assert [NUMERICS + "/step_error.h", "include/birkhoff_cart/core/cart_model.h"] in chains
    assert len(chains) == 2


def test_an_unresolvable_include_is_refused_by_name(tmp_path):
    numerics = tmp_path / NUMERICS
    numerics.mkdir(parents=True)
    (numerics / "dopri5.h").write_text('#include "nowhere.h"\n')
    with pytest.raises(AssertionError, match='dopri5.h: cannot resolve #include "nowhere.h"'):
        system_chains(tmp_path)

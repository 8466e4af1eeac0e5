"""The integrator registry as `cart_simulate --list-integrators --json` lists it: the members (name,
order, symmetric, reversible, adaptive, kind, whether they read a tolerance), the Birkhoffian forms and the
step controls. A study reads it from the binary it runs, so the Python side keeps no second list."""
import dataclasses
import json
import subprocess
from typing import List, Tuple


@dataclasses.dataclass(frozen=True)
class Member:
    name: str
    order: int
    symmetric: bool
    reversible: bool       # takes --step-control reversible
    adaptive: bool         # takes --step-control adaptive
    kind: str              # "Birkhoffian collocation", "composition", "explicit RK", "adaptive", ...
    takes_tolerance: bool  # reads --tolerance (its own steps inside h) instead of stepping at h alone


@dataclasses.dataclass(frozen=True)
class Registry:
    members: Tuple[Member, ...]
    forms: Tuple[str, ...]
    step_controls: Tuple[str, ...]

    @property
    def names(self) -> List[str]:
        return [member.name for member in self.members]

    @property
    def adaptive(self) -> List[str]:
        """The members with their own steps inside h: they read a tolerance instead of a step."""
        return [member.name for member in self.members if member.takes_tolerance]

    def member(self, name):
        return next((m for m in self.members if m.name == name), None)


def parse_listing(text):
    """The Registry in the JSON `cart_simulate --list-integrators --json` prints; ValueError naming
    what is missing when the text is not such a listing."""
    try:
        listing = json.loads(text)
        members = tuple(Member(str(m["name"]), int(m["order"]), bool(m["symmetric"]), bool(m["reversible"]),
                               bool(m["adaptive"]), str(m["kind"]), bool(m["takes_tolerance"]))
                        for m in listing["integrators"])
        forms = tuple(str(f) for f in listing["birkhoffian_forms"])
        controls = tuple(str(c) for c in listing["step_controls"])
    except (ValueError, KeyError, TypeError) as error:
        raise ValueError("cart_simulate --list-integrators --json printed no registry listing (%s: %s)"
                         % (type(error).__name__, str(error)[:100]))
    if not members or not forms or not controls:
        raise ValueError("cart_simulate --list-integrators --json lists no integrators, forms or step controls")
    return Registry(members, forms, controls)


def read_registry(cart_simulate):
    """The Registry of the cart_simulate executable at `cart_simulate`."""
    result = subprocess.run([cart_simulate, "--list-integrators", "--json"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, universal_newlines=True, timeout=60)
    if result.returncode != 0:
        raise ValueError("%s --list-integrators --json failed (exit %d): %s"
                         % (cart_simulate, result.returncode, result.stderr.strip()[:200]))
    return parse_listing(result.stdout)

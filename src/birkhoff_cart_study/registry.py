"""The integrator registry as `cart_simulate --help` shows it: the members (name, order, symmetric,
reversible, kind) in the help's order, the Birkhoffian forms and the step controls. A study reads it
from the binary it runs, so the Python side keeps no second list of them."""
import collections
import re
import subprocess

Member = collections.namedtuple("Member", "name order symmetric reversible kind")


class Registry(collections.namedtuple("Registry", "members forms step_controls")):
    """members: Member tuples; forms, step_controls: their texts on the command line."""

    @property
    def names(self):
        return [member.name for member in self.members]

    @property
    def adaptive(self):
        """The members with their own steps inside h: they read a tolerance instead of a step."""
        return [member.name for member in self.members if member.kind == "adaptive"]


HEADER = re.compile(r"^  NAME +p +symmetric +reversible +(?:vector +)?kind +scheme$", re.M)
ROW = re.compile(r"^  ([a-z][a-z0-9_]*) +(\d+) +(yes|no) +(yes|no) +(.*)$")


def parse_help(text):
    """The Registry in the text `cart_simulate --help` prints; ValueError if the text has none."""
    header = HEADER.search(text)
    if header is None:
        raise ValueError("cart_simulate --help shows no integrator table (a line '  NAME  p  symmetric ...')")
    kind_column = header.group(0).index("kind")
    scheme_column = header.group(0).index("scheme")
    members = []
    for line in text[header.end() + 1:].splitlines():
        row = ROW.match(line)
        if row is None:
            break
        members.append(Member(row.group(1), int(row.group(2)), row.group(3) == "yes", row.group(4) == "yes",
                              line[kind_column:scheme_column].strip()))
    forms = re.search(r"^  --birkhoffian-form F +(.+)$", text, re.M)
    controls = re.search(r"\[--step-control ([a-z|]+)\]", text)
    if not members or forms is None or controls is None:
        raise ValueError("cart_simulate --help lacks the integrators, the forms or the step controls")
    return Registry(members, re.split(r",\s*|\s+or\s+", forms.group(1).strip()), controls.group(1).split("|"))


def read_registry(cart_simulate):
    """The Registry of the cart_simulate executable at `cart_simulate`."""
    text = subprocess.run([cart_simulate, "--help"], stdout=subprocess.PIPE, universal_newlines=True,
                          check=True).stdout
    return parse_help(text)

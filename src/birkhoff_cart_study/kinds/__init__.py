"""The study kinds: one module each, with its schema, its smoke size, its expansion into tasks, its
command line (wire), its outcome (run on the worker: run) and its report. KINDS is the one table the runner dispatches on."""
from ..tasks import StudyKind
from . import cli_runs, random_carts, work_precision

KINDS = {module.KIND: module for module in (work_precision, cli_runs, random_carts)}
NAMES = [kind.value for kind in KINDS]


def module_of(kind):
    """The module of a StudyKind (or of its name)."""
    return KINDS[StudyKind(kind)]

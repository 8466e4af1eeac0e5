"""The study kinds: one module each, with its schema, its smoke size, its expansion into tasks, its
command line (wire), its outcome (run on the worker: run) and its report. A module of this package
that defines KIND (a StudyKind) is that kind's; the others (simulate, work_precision_report) are
shared parts. KINDS, found from the package's modules, is the one table the runner dispatches on."""
import importlib
import pkgutil

from ..tasks import StudyKind

MODULES = [importlib.import_module("%s.%s" % (__name__, info.name)) for info in pkgutil.iter_modules(__path__)]
_BY_KIND = {module.KIND: module for module in MODULES if hasattr(module, "KIND")}
KINDS = {kind: _BY_KIND[kind] for kind in StudyKind if kind in _BY_KIND}  # in StudyKind's order
NAMES = [kind.value for kind in KINDS]


def module_of(kind):
    """The module of a StudyKind (or of its name)."""
    return KINDS[StudyKind(kind)]

"""A study file, read and checked before anything runs: the YAML within the caps (study_yaml.py),
the kind, the kind's schema (schema.py, kinds/*.py), the kind's own checks, then its tasks.

    study, tasks = load_study(path, registry, scene_dir, smoke=False)

`study` is the checked document (a dict, with the experiments' labels in order under "labels");
`tasks` the Task list, each with its id. Every refusal is a StudyError naming the file and the key."""
import difflib

from . import schema
from .kinds import NAMES, module_of
from .limits import StudyError, quoted
from .study_yaml import read_study_yaml
from .tasks import task_id

DEFAULT_TIME_LIMIT = 3600.0  # [s] of wall time per task


def _kind(path, doc):
    if not isinstance(doc, dict):
        raise StudyError("study %s: the file must be a map (name, kind, experiments, ...), got %s" % (path, quoted(doc)))
    if "kind" not in doc:
        if "engine" in doc:
            schema.refuse(path, ("engine",), "'engine' is now 'kind': %s" % ", ".join(NAMES))
        schema.refuse(path, ("kind",), "required (%s)" % ", ".join(NAMES))
    kind = doc["kind"]
    if kind not in NAMES:
        match = difflib.get_close_matches(kind, NAMES, n=1) if isinstance(kind, str) else []
        schema.refuse(path, ("kind",), "must be %s, got %s%s" % (", ".join(NAMES), quoted(kind),
                                                                 " (did you mean '%s'?)" % match[0] if match else ""))
    return module_of(kind)


def load_study(path, registry, scene_dir, smoke=False):
    """Reads and checks the study at `path`; returns (study document, tasks). With `smoke`, the study
    at its smoke size (each kind's `smoke`: a few tasks of every experiment)."""
    doc = read_study_yaml(path)
    kind = _kind(path, doc)
    schema.check(path, doc, kind.schema(registry))
    doc["time_limit"] = float(doc.get("time_limit", DEFAULT_TIME_LIMIT))
    doc.setdefault("description", "")
    if smoke:
        doc = kind.smoke(doc)
    tasks = kind.expand(path, doc, {"registry": registry, "scene_dir": scene_dir})
    seen = {}
    for task in tasks:
        task.id = task_id(task)
        if task.id in seen:
            schema.refuse(path, ("experiments",), "two tasks with the same settings (%s %s)"
                          % (task.label, task.settings.get("method", "")))
        seen[task.id] = task
    doc["labels"] = list(dict.fromkeys(t.label for t in tasks if t.kind.value in ("measure", "simulate")))
    return doc, tasks

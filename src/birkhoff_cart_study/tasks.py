"""Tasks: one process of the batch engine each, made by a study kind's expansion (kinds/*.py).

A task travels to a Dask worker as its `wire` dict (plain values only: workers need nothing of
this package but what the task carries) and comes back as a row: the task's fields plus what the
process did (task_runner.py). Its id is a hash of its fields and of its scene's text, so a study
resumed with the same file runs only the tasks without a row."""
import dataclasses
import enum
import hashlib
import json
from typing import Any, Dict


class StudyKind(enum.Enum):
    """What a study is about; one module of kinds/ each."""
    WORK_PRECISION = "work_precision"  # work_precision --measure against references
    CLI_RUNS = "cli_runs"              # cart_simulate runs: a product of settings, or seeded random runs
    RANDOM_CARTS = "random_carts"      # cart_simulate on random valid carts of the seeded family


class TaskKind(enum.Enum):
    """What one task's process does; the row's "type"."""
    MEASURE = "measure"                  # work_precision --measure: one method at one setting
    REFERENCE = "reference"              # work_precision --reference-run: the states errors are measured against
    REFERENCE_CHECK = "reference_check"  # the independent run the reference must agree with
    SIMULATE = "simulate"                # one cart_simulate run


@dataclasses.dataclass
class Task:
    kind: TaskKind
    study_kind: StudyKind
    study: str           # the study's name
    label: str           # the experiment's label (a reference's name for reference tasks)
    scene: str           # the scene file's name, for rows and tables (the worker writes it as this name)
    scene_text: str      # the scene file's text: the scene travels inside the task
    time_limit: float    # [s] of wall time; past it the process is killed and the row is a timeout
    settings: Dict[str, Any] = dataclasses.field(default_factory=dict)  # the kind's own (method, step, ...)
    id: str = ""

    def fields(self):
        """The task's part of its row: type, study, label, scene, time_limit and the kind's settings."""
        row = {"type": self.kind.value, "study": self.study, "label": self.label, "scene": self.scene,
               "time_limit": self.time_limit}
        row.update(self.settings)
        return row

    def wire(self):
        """The fields and the id: what a worker needs, but for the command line and the files the
        study kind adds (kinds/*.py: wire)."""
        return dict(self.fields(), id=self.id)

    def get(self, key, default=None):
        return self.fields().get(key, default)


_scene_hashes = {}


def _scene_sha1(text):
    digest = _scene_hashes.get(text)
    if digest is None:
        digest = _scene_hashes[text] = hashlib.sha1(text.encode()).hexdigest()
    return digest


def task_id(task):
    """A stable identity of a task's settings: resuming skips the ids already in the rows."""
    settings = task.fields()
    settings["scene_sha1"] = _scene_sha1(task.scene_text)
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(text.encode()).hexdigest()[:16]

"""The work_precision study kind: what accuracy costs in time. Each task is one process of the
work_precision executable: `--measure` (one method at one setting, timed over `repetitions` runs,
its errors against the reference states at the checkpoints) or `--reference-run` (a reference, or
the independent run it is checked against: references.py).

The methods are the registry's members (cart_simulate --list-integrators --json) and Boost.Odeint's
peers. A method's runs sweep the settings of RUN_SETTINGS; the schema, the expansion, the command
line and the report's setting text all read that table, so a new per-method setting is one line."""
import dataclasses
import itertools
import json
import math
import os
from typing import Callable

from .. import schema as s
from .. import scenes
from ..task_runner import run_task
from ..tasks import StudyKind, Task, TaskKind

KIND = StudyKind.WORK_PRECISION
REFERENCE_KINDS = ("extended_precision", "dopri5", "analytic")
# The run a reference is checked against (work_precision --reference-run --check-setting; reference.h).
CHECKS = {"extended_precision": "long_double_bulirsch_stoer_tol_1e-18", "dopri5": "dopri5_tol_1e-12"}
ODEINT_PEERS = {"odeint_rk4": False, "odeint_dopri5": True, "odeint_rkf78": True, "odeint_bulirsch_stoer": True,
                "odeint_bulirsch_stoer_dense_out": True}  # Boost.Odeint's peers: name → reads a tolerance
SMOKE_DURATION = 10.0  # --smoke: [s] of simulated time at most per experiment and reference


@dataclasses.dataclass(frozen=True)
class Method:
    name: str
    ours: bool              # a registry member (run through Simulation), not a Boost.Odeint peer
    takes_tolerance: bool   # an adaptive method: its own steps for a tolerance
    reversible: bool        # takes the reversible step control (registry)


@dataclasses.dataclass(frozen=True)
class RunSetting:
    field: str       # the task's (and row's) key
    option: str      # work_precision's option
    label: str       # how the report's setting text names it
    primary: bool    # a sweep axis: one primary setting per task (work_precision takes one of them)
    takes: Callable[[Method], bool]  # which methods take it
    methods: str     # those methods, for a refusal


# The per-method settings a run may sweep: study key → RunSetting. A new setting is one line here.
RUN_SETTINGS = {
    "steps": RunSetting("step", "--step", "h", True, lambda m: not m.takes_tolerance, "the fixed-step methods"),
    "tolerances": RunSetting("tolerance", "--tolerance", "tol", True, lambda m: m.takes_tolerance,
                             "the adaptive methods"),
    "simulator_steps": RunSetting("simulator_step", "--simulator-step", "sim step", False,
                                  lambda m: m.ours and m.takes_tolerance, "our adaptive members (dopri5)"),
}


def methods(registry):
    """Every method a run may name: the registry's members, Boost.Odeint's peers, then each member
    under the step controls it takes (NAME_adaptive, NAME_reversible: their own steps for a position
    tolerance, swept as `tolerances`)."""
    known = {m.name: Method(m.name, True, m.takes_tolerance, m.reversible) for m in registry.members}
    known.update({name: Method(name, False, adaptive, False) for name, adaptive in ODEINT_PEERS.items()})
    for m in registry.members:  # last, so that a refusal lists the plain names first
        for control, offered in (("adaptive", m.adaptive), ("reversible", m.reversible)):
            if offered:
                name = "%s_%s" % (m.name, control)
                known[name] = Method(name, True, True, False)
    return known


def schema(registry):
    checkpoints = s.increasing_list(1e7, " [s]")
    reference = {
        "type": "object", "additionalProperties": False, "required": ["kind"],
        "properties": {"kind": s.names_of(REFERENCE_KINDS, "reference kind"), "scene": s.SCENE,
                       "duration": s.DURATION, "checkpoints": checkpoints},
        "if": {"properties": {"kind": {"const": "analytic"}}},
        "then": {"properties": {key: s.forbidden("not with kind analytic (the closed form needs no run)")
                                for key in ("scene", "duration", "checkpoints")}},
        "else": {"required": ["scene", "duration"]}}
    run = s.strict_map({key: s.positive_list() for key in RUN_SETTINGS}, minProperties=1)
    experiment = s.strict_map({
        "label": s.name("a label"), "scene": s.SCENE, "duration": s.DURATION, "reference": s.name("a reference"),
        "checkpoints": checkpoints,
        "runs": {"type": "object", "minProperties": 1, "maxProperties": 200, "additionalProperties": run,
                 "propertyNames": s.names_of(list(methods(registry)), "integrator")}},
        ("label", "scene", "duration", "reference", "runs"))
    extra = {"repetitions": s.whole(1, 1000),
             "references": {"type": "object", "minProperties": 1, "maxProperties": 100,
                            "propertyNames": s.name("a reference name"), "additionalProperties": reference}}
    return s.study(KIND.value, experiment, extra, required=("references",))


def smoke(doc):
    """The study at smoke size: one repetition, each method at its loosest setting only (the largest
    value of each list), durations cut to SMOKE_DURATION with the checkpoints past it dropped."""
    doc["repetitions"] = 1

    def cut(item):
        if "duration" in item and item["duration"] > SMOKE_DURATION:
            item["duration"] = SMOKE_DURATION
            if "checkpoints" in item:
                item["checkpoints"] = [t for t in item["checkpoints"] if t < SMOKE_DURATION]
    for reference in doc["references"].values():
        cut(reference)
    for experiment in doc["experiments"]:
        cut(experiment)
        experiment["runs"] = {method: {key: [max(values)] for key, values in settings.items()}
                              for method, settings in experiment["runs"].items()}
    return doc


def _checkpoints(path, parts, values, duration):
    points = list(values or [])
    if any(b <= a for a, b in zip(points, points[1:])):
        s.refuse(path, parts, "must increase")
    if points and points[-1] > duration * (1 + 1e-12):
        s.refuse(path, parts, "must not pass the duration %g s" % duration)
    if not points or abs(points[-1] - duration) > 1e-12 * duration:
        points.append(float(duration))
    return [float(t) for t in points]


def _references(path, doc, context):
    """{name: (reference task, check task) or None for the closed form}."""
    out = {}
    for name, ref in doc["references"].items():
        where = ("references", name)
        if ref["kind"] == "analytic":
            out[name] = None
            continue
        scene_file = scenes.resolve(path, where + ("scene",), ref["scene"], context["scene_dir"])
        settings = {"reference_kind": ref["kind"], "duration": float(ref["duration"]),
                    "checkpoints": _checkpoints(path, where + ("checkpoints",), ref.get("checkpoints"), ref["duration"])}
        text = scenes.text_of(path, where + ("scene",), scene_file)
        make = lambda kind, extra: Task(kind, KIND, doc["name"], name, os.path.basename(scene_file), text,  # noqa: E731
                                        doc.get("time_limit", 3600.0), dict(settings, **extra))
        out[name] = (make(TaskKind.REFERENCE, {}), make(TaskKind.REFERENCE_CHECK, {"check": CHECKS[ref["kind"]]}))
    return out


def _run_settings(path, parts, method, settings):
    """[{field: value}] of one method's runs: each primary setting's values, times the product of
    the others'. Refuses a setting the method does not take, and a method without a primary one."""
    takes = [key for key, setting in RUN_SETTINGS.items() if setting.primary and setting.takes(method)]
    for key in settings:
        if not RUN_SETTINGS[key].takes(method):
            s.refuse(path, parts + (key,), "%s does not take %s (they are for %s)%s"
                     % (method.name, key, RUN_SETTINGS[key].methods, "; it takes %s" % " or ".join(takes) if takes else ""))
    primaries = [key for key in settings if RUN_SETTINGS[key].primary]
    if not primaries:
        s.refuse(path, parts + (takes[0] if takes else "steps",), "required for %s (give %s)"
                 % (method.name, " or ".join(takes) or "a setting it takes"))
    others = [[(RUN_SETTINGS[key].field, float(v)) for v in settings[key]] for key in settings
              if not RUN_SETTINGS[key].primary]
    return [dict([(RUN_SETTINGS[key].field, float(value))] + list(rest))
            for key in primaries for value in settings[key] for rest in itertools.product(*others)]


def expand(path, doc, context):
    """The references, their checks and every measurement; refusals name the key."""
    known = methods(context["registry"])
    s.cap_tasks(path, [sum(math.prod(len(values) for values in settings.values())
                           for settings in experiment["runs"].values()) for experiment in doc["experiments"]])
    s.unique_labels(path, doc["experiments"])
    references = _references(path, doc, context)
    tasks = [task for pair in references.values() if pair for task in pair]
    for i, experiment in enumerate(doc["experiments"]):
        where = ("experiments", i)
        label = experiment["label"]
        scene_file = scenes.resolve(path, where + ("scene",), experiment["scene"], context["scene_dir"])
        name = experiment["reference"]
        if name not in references:
            s.refuse(path, where + ("reference",), "no reference named '%s' under 'references' (known: %s)"
                     % (name, ", ".join(references)))
        duration = float(experiment["duration"])
        checkpoints = _checkpoints(path, where + ("checkpoints",), experiment.get("checkpoints"), duration)
        pair = references[name]
        if pair is not None:
            reference = pair[0]
            if os.path.basename(scene_file) != reference.scene:
                s.refuse(path, where + ("reference",), "reference '%s' is of scene %s, not %s"
                         % (name, reference.scene, os.path.basename(scene_file)))
            for t in checkpoints:
                if not any(abs(t - r) <= 1e-9 * t for r in reference.settings["checkpoints"]):
                    s.refuse(path, where + ("checkpoints",), "reference '%s' has no state at %g s (its checkpoints: %s)"
                             % (name, t, ", ".join("%g" % r for r in reference.settings["checkpoints"])))
        text = scenes.text_of(path, where + ("scene",), scene_file)
        for method_name, settings in experiment["runs"].items():
            for run in _run_settings(path, where + ("runs", method_name), known[method_name], settings):
                task_settings = dict(run, method=method_name, duration=duration, checkpoints=checkpoints, reference=name,
                                     repetitions=doc.get("repetitions", 3))
                if pair is None:
                    task_settings["analytic"] = True
                tasks.append(Task(TaskKind.MEASURE, KIND, doc["name"], label, os.path.basename(scene_file), text,
                                  doc.get("time_limit", 3600.0), task_settings))
    return tasks


def wire(task, bin_dir):
    """The task as a worker runs it: work_precision on the task's scene, the reference file (a
    measurement's, from its reference task) written beside it as reference.csv."""
    settings = task.settings
    argv = [os.path.join(bin_dir, "work_precision"), "--scene", task.scene, "--duration", repr(settings["duration"]),
            "--checkpoints", ",".join(repr(t) for t in settings["checkpoints"]), "--label", task.label]
    if task.kind in (TaskKind.REFERENCE, TaskKind.REFERENCE_CHECK):
        argv += ["--reference-run", "--reference-kind", settings["reference_kind"], "--output", "reference.csv"]
        if task.kind == TaskKind.REFERENCE_CHECK:
            argv.append("--check-setting")
    else:
        argv += ["--measure", "--method", settings["method"], "--repetitions", str(settings["repetitions"])]
        for setting in RUN_SETTINGS.values():
            if setting.field in settings:
                argv += [setting.option, repr(settings[setting.field])]
        argv += ["--analytic-reference"] if settings.get("analytic") else ["--reference-file", "reference.csv"]
    needs = task.kind == TaskKind.MEASURE and not settings.get("analytic")
    return dict(task.wire(), argv=argv, files={task.scene: task.scene_text}, needs_reference=needs)


def outcome(wire, process):
    """ok with the engine's JSON row as `result` (a reference's file as `reference_text`);
    step_failed when the method could not step the run (a measured result, exit 4); else failed."""
    row = {}
    result = None
    if not process.timed_out and process.stdout.strip():
        try:
            result = json.loads(process.stdout.strip().splitlines()[-1])
        except ValueError:
            result = None
    if result is not None:
        row["result"] = result
    if process.timed_out:
        return row
    if process.status == 0 and isinstance(result, dict):
        row["outcome"] = "ok"
        if wire["type"] in ("reference", "reference_check"):
            try:
                with open(process.path("reference.csv")) as f:
                    row["reference_text"] = f.read()
            except OSError as error:
                row.update(outcome="failed", reason="no reference file: %s" % error.strerror)
    elif process.status == 4 and isinstance(result, dict):
        # The process worked and measured that the method cannot step this run (a step failed:
        # too large a step, a singularity): a result of the study, not a failure.
        row["outcome"] = "step_failed"
        row["reason"] = str(result.get("status"))
    else:
        row["outcome"] = "failed"
        row["reason"] = str((result or {}).get("status") if isinstance(result, dict) else "") or \
            "exit status %d" % process.status
    return row


def run(wire, reference=None):
    """One task on a worker (what the runner submits; Dask sends it by value): its row."""
    return run_task(wire, outcome, reference)


def report(study, rows, directory, stem):
    from . import work_precision_report
    return work_precision_report.report(study, rows, directory, stem, RUN_SETTINGS)

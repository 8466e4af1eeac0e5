"""Study files: read, validate (every error names the key), and expand into tasks.

A study file is one YAML map (docs/studies.md has the full schema):

    name: work_precision            # the study's name (rows, reports)
    engine: work_precision          # work_precision (measurements) or cart_simulate (runs of the CLI)
    repetitions: 3                  # timed runs per measurement; the median CPU time is reported
    time_limit: 1800                # [s] of wall time per task; past it the task is a failed row
    references:                     # work_precision: what errors are measured against
      whirl: {scene: jackknife_whirl, duration: 10000, kind: extended_precision, checkpoints: [...]}
      paper: {kind: analytic}
    experiments:
      - label: jackknife_whirl_1000s
        scene: jackknife_whirl      # a shipped scene name, or a path to a scene file
        duration: 1000              # [s]
        reference: whirl
        checkpoints: [1, 10, 100, 1000]
        runs:                       # method: its settings
          birkhoff_gauss8: {steps: [0.2, 0.1]}
          odeint_rkf78: {tolerances: [1.0e-8, 1.0e-10]}

For engine cart_simulate an experiment lists `scenes`, `integrators` and optional `steps`,
`tolerances`, `durations`, `step_control`, `birkhoffian_forms`, `output_rates`: the task list is
their product.
"""
import hashlib
import json
import math
import os

import yaml

from .cli_contract import random_runs, with_start_time

ENGINES = ("work_precision", "cart_simulate")
REFERENCE_KINDS = ("extended_precision", "dopri5", "analytic")
ODEINT_PEERS = ("odeint_rk4", "odeint_dopri5", "odeint_rkf78", "odeint_bulirsch_stoer",
                "odeint_bulirsch_stoer_dense_out")
ODEINT_FIXED_STEP = ("odeint_rk4",)

TOP_KEYS = {"name", "description", "engine", "repetitions", "time_limit", "references", "experiments"}
REFERENCE_KEYS = {"scene", "duration", "kind", "checkpoints"}
MEASURE_EXPERIMENT_KEYS = {"label", "scene", "duration", "reference", "checkpoints", "runs"}
RUN_KEYS = {"steps", "tolerances", "simulator_steps"}
RANDOM_KEYS = {"seed", "count", "first", "base"}
RANDOM_RUN_KEYS = {"seed", "count", "scenes"}
CLI_REFERENCE_KEYS = {"integrator", "step"}
CLI_EXPERIMENT_KEYS = {"label", "scenes", "random_scenes", "random_runs", "integrators", "end_only", "reference", "steps", "tolerances", "durations", "step_control",
                       "birkhoffian_forms", "output_rates", "expect"}


class StudyError(ValueError):
    """A study file that cannot be run; the message names the file and the key."""


def _fail(path, key, message):
    raise StudyError("study %s: key '%s': %s" % (path, key, message))


def _check_keys(path, where, mapping, allowed):
    if not isinstance(mapping, dict):
        _fail(path, where, "must be a map, got %r" % (mapping,))
    for key in mapping:
        if key not in allowed:
            _fail(path, "%s.%s" % (where, key) if where else key,
                  "unknown key (known: %s)" % ", ".join(sorted(allowed)))


def _positive(path, key, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        _fail(path, key, "must be a finite number > 0, got %r" % (value,))
    return float(value)


def _positive_list(path, key, values):
    if not isinstance(values, list) or not values:
        _fail(path, key, "must be a non-empty list of numbers > 0, got %r" % (values,))
    return [_positive(path, "%s[%d]" % (key, i), v) for i, v in enumerate(values)]


def _string_list(path, key, values, allowed=None):
    if isinstance(values, str):
        values = [values]
    if not isinstance(values, list) or not values or not all(isinstance(v, str) for v in values):
        _fail(path, key, "must be a name or a non-empty list of names, got %r" % (values,))
    if allowed is not None:
        for v in values:
            if v not in allowed:
                _fail(path, key, "unknown name '%s' (known: %s)" % (v, ", ".join(allowed)))
    return values


def resolve_scene(path, key, scene, scene_dir):
    """A shipped scene name (config/scenes/NAME.yaml) or a path; returns the file's absolute path."""
    if not isinstance(scene, str) or not scene:
        _fail(path, key, "must be a scene name or a path, got %r" % (scene,))
    candidates = [scene] if scene.endswith((".yaml", ".yml")) else []
    candidates.append(os.path.join(scene_dir, scene + ".yaml"))
    base = os.path.dirname(os.path.abspath(path))
    for candidate in candidates:
        for full in (candidate, os.path.join(base, candidate)):
            if os.path.isfile(full):
                return os.path.abspath(full)
    _fail(path, key, "unknown scene '%s' (no %s)" % (scene, " or ".join(candidates)))


def task_id(task):
    """A stable identity of a task's settings: resuming skips the ids already in the rows."""
    settings = {k: v for k, v in task.items() if k not in ("scene_text", "id")}
    settings["scene_sha1"] = hashlib.sha1(task.get("scene_text", "").encode()).hexdigest()
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _checkpoints(path, key, values, duration):
    points = _positive_list(path, key, values) if values is not None else []
    if any(b <= a for a, b in zip(points, points[1:])):
        _fail(path, key, "must increase")
    if points and points[-1] > duration * (1 + 1e-12):
        _fail(path, key, "must not pass the duration %g s" % duration)
    if not points or abs(points[-1] - duration) > 1e-12 * duration:
        points.append(duration)
    return points


def load_study(path, registry, scene_dir):
    """Reads and validates the study at `path`; returns (study settings, list of task dicts).

    `registry` is the integrator registry (registry.read_registry: `cart_simulate --help`), `scene_dir` the shipped
    scenes' directory. Nothing runs before the whole file has been checked."""
    try:
        with open(path) as f:
            doc = yaml.safe_load(f)
    except OSError as error:
        raise StudyError("study %s: cannot read it: %s" % (path, error.strerror))
    except yaml.YAMLError as error:
        raise StudyError("study %s: not valid YAML: %s" % (path, str(error).replace("\n", " ")))
    _check_keys(path, "", doc, TOP_KEYS)
    for key in ("name", "engine", "experiments"):
        if key not in doc:
            _fail(path, key, "required")
    name = doc["name"]
    if not isinstance(name, str) or not name.replace("_", "").replace("-", "").isalnum():
        _fail(path, "name", "must be a word of letters, digits, '_' and '-', got %r" % (name,))
    engine = doc["engine"]
    if engine not in ENGINES:
        _fail(path, "engine", "must be one of %s, got %r" % (", ".join(ENGINES), engine))
    repetitions = doc.get("repetitions", 3)
    if isinstance(repetitions, bool) or not isinstance(repetitions, int) or not 1 <= repetitions <= 1000:
        _fail(path, "repetitions", "must be a whole number in 1..1000, got %r" % (repetitions,))
    time_limit = _positive(path, "time_limit", doc.get("time_limit", 3600))
    study = {"name": name, "engine": engine, "repetitions": repetitions, "time_limit": time_limit,
             "description": doc.get("description", "")}
    experiments = doc["experiments"]
    if not isinstance(experiments, list) or not experiments:
        _fail(path, "experiments", "must be a non-empty list")
    if engine == "work_precision":
        tasks = _measurement_tasks(path, doc, experiments, registry, scene_dir, study)
    else:
        if "references" in doc:
            _fail(path, "references", "only for engine work_precision")
        tasks = _cli_tasks(path, experiments, registry, scene_dir, study)
    ids = set()
    for task in tasks:
        task["id"] = task_id(task)
        if task["id"] in ids:
            _fail(path, "experiments", "two tasks with the same settings (%s %s)" % (task.get("label"), task.get("method", "")))
        ids.add(task["id"])
    return study, tasks


def _measurement_tasks(path, doc, experiments, registry, scene_dir, study):
    references = doc.get("references", {})
    _check_keys(path, "references", references, set(references) if isinstance(references, dict) else set())
    reference_tasks = {}
    for ref_name, ref in references.items():
        where = "references.%s" % ref_name
        _check_keys(path, where, ref, REFERENCE_KEYS)
        kind = ref.get("kind")
        if kind not in REFERENCE_KINDS:
            _fail(path, where + ".kind", "must be one of %s, got %r" % (", ".join(REFERENCE_KINDS), kind))
        if kind == "analytic":
            reference_tasks[ref_name] = None
            continue
        for key in ("scene", "duration"):
            if key not in ref:
                _fail(path, "%s.%s" % (where, key), "required for kind %s" % kind)
        duration = _positive(path, where + ".duration", ref["duration"])
        scene_file = resolve_scene(path, where + ".scene", ref["scene"], scene_dir)
        reference_tasks[ref_name] = {
            "type": "reference", "study": study["name"], "label": ref_name, "reference_kind": kind,
            "scene": os.path.basename(scene_file), "scene_text": open(scene_file).read(),
            "duration": duration, "checkpoints": _checkpoints(path, where + ".checkpoints", ref.get("checkpoints"), duration),
            "time_limit": study["time_limit"]}
    known_methods = registry.names + list(ODEINT_PEERS)
    our_adaptive = registry.adaptive
    tasks = []
    for reference in reference_tasks.values():
        if reference is not None:
            # The setting the reference is checked against runs as a task of its own, in parallel:
            # the measurements wait only for the reference.
            tasks += [reference, dict(reference, type="reference_check")]
    labels = set()
    for i, experiment in enumerate(experiments):
        where = "experiments[%d]" % i
        _check_keys(path, where, experiment, MEASURE_EXPERIMENT_KEYS)
        for key in ("label", "scene", "duration", "reference", "runs"):
            if key not in experiment:
                _fail(path, "%s.%s" % (where, key), "required")
        label = experiment["label"]
        if not isinstance(label, str) or not label or label in labels:
            _fail(path, where + ".label", "must be a name of its own, got %r" % (label,))
        labels.add(label)
        duration = _positive(path, where + ".duration", experiment["duration"])
        scene_file = resolve_scene(path, where + ".scene", experiment["scene"], scene_dir)
        ref_name = experiment["reference"]
        if ref_name not in reference_tasks:
            _fail(path, where + ".reference", "no reference named %r under 'references'" % (ref_name,))
        reference = reference_tasks[ref_name]
        checkpoints = _checkpoints(path, where + ".checkpoints", experiment.get("checkpoints"), duration)
        if reference is not None:
            if os.path.basename(scene_file) != reference["scene"]:
                _fail(path, where + ".reference", "reference %r is of scene %s, not %s"
                      % (ref_name, reference["scene"], os.path.basename(scene_file)))
            for t in checkpoints:
                if not any(abs(t - r) <= 1e-9 * t for r in reference["checkpoints"]):
                    _fail(path, where + ".checkpoints", "reference %r has no state at %g s (its checkpoints: %s)"
                          % (ref_name, t, reference["checkpoints"]))
        runs = experiment["runs"]
        _check_keys(path, where + ".runs", runs, set(runs) if isinstance(runs, dict) else set())
        if not runs:
            _fail(path, where + ".runs", "must name at least one method")
        scene_text = open(scene_file).read()
        for method, settings in runs.items():
            run_where = "%s.runs.%s" % (where, method)
            if method not in known_methods:
                _fail(path, run_where, "unknown integrator (known: %s)" % ", ".join(known_methods))
            _check_keys(path, run_where, settings, RUN_KEYS)
            fixed_step = method not in our_adaptive and method not in ODEINT_PEERS or method in ODEINT_FIXED_STEP
            if fixed_step:
                if "tolerances" in settings:
                    _fail(path, run_where + ".tolerances", "%s takes steps, not tolerances" % method)
                if "steps" not in settings:
                    _fail(path, run_where + ".steps", "required for the fixed-step method %s" % method)
                values = [("step", h) for h in _positive_list(path, run_where + ".steps", settings["steps"])]
            else:
                if "steps" in settings:
                    _fail(path, run_where + ".steps", "%s takes tolerances, not steps" % method)
                if "tolerances" not in settings:
                    _fail(path, run_where + ".tolerances", "required for the adaptive method %s" % method)
                values = [("tolerance", tol) for tol in _positive_list(path, run_where + ".tolerances", settings["tolerances"])]
            simulator_steps = [None]
            if "simulator_steps" in settings:
                if method not in our_adaptive:
                    _fail(path, run_where + ".simulator_steps", "only for our dopri5")
                simulator_steps = _positive_list(path, run_where + ".simulator_steps", settings["simulator_steps"])
            for simulator_step in simulator_steps:
                for setting, value in values:
                    task = {"type": "measure", "study": study["name"], "label": label, "method": method,
                            "scene": os.path.basename(scene_file), "scene_text": scene_text, "duration": duration,
                            "checkpoints": checkpoints, "reference": ref_name,
                            "repetitions": study["repetitions"], "time_limit": study["time_limit"], setting: value}
                    if simulator_step is not None:
                        task["simulator_step"] = simulator_step
                    if reference is None:
                        task["analytic"] = True
                    tasks.append(task)
    return tasks


def _whole(path, key, value, least):
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        _fail(path, key, "must be a whole number ≥ %d, got %r" % (least, value))
    return value


def _random_run_tasks(path, where, experiment, registry, scene_dir, study):
    """The seeded random runs of the CLI contract (cli_contract.random_runs): random scenes, start
    times, durations, steps, output rates, integrators, tolerances and forms."""
    allowed = {"label", "random_runs", "integrators"}
    for key in experiment:
        if key not in allowed:
            _fail(path, "%s.%s" % (where, key), "not with random_runs (known: %s)" % ", ".join(sorted(allowed)))
    family = experiment["random_runs"]
    _check_keys(path, where + ".random_runs", family, RANDOM_RUN_KEYS)
    seed = _whole(path, where + ".random_runs.seed", family.get("seed"), 0)
    count = _whole(path, where + ".random_runs.count", family.get("count"), 1)
    names = family.get("scenes") or sorted(f[:-5] for f in os.listdir(scene_dir) if f.endswith(".yaml"))
    files = {n: resolve_scene(path, where + ".random_runs.scenes", n, scene_dir)
             for n in _string_list(path, where + ".random_runs.scenes", names)}
    methods = (_string_list(path, where + ".integrators", experiment["integrators"], registry.names)
               if "integrators" in experiment else registry.names)
    texts = {n: open(f).read() for n, f in files.items()}
    tasks = []
    for index, run in enumerate(random_runs(seed, count, sorted(files), methods, registry.adaptive, registry.forms)):
        text = with_start_time(texts[run["scene"]], run["start_time"])
        if text is None:
            _fail(path, where + ".random_runs.scenes", "scene %s has no initial_state time line" % run["scene"])
        task = dict(run, type="simulate", study=study["name"], label=experiment["label"], index=index,
                    scene=os.path.basename(files[run["scene"]]), scene_text=text, step_control="fixed",
                    expect="finish_or_refuse", time_limit=study["time_limit"])
        tasks.append(task)
    return tasks


def _cli_tasks(path, experiments, registry, scene_dir, study):
    tasks = []
    for i, experiment in enumerate(experiments):
        where = "experiments[%d]" % i
        _check_keys(path, where, experiment, CLI_EXPERIMENT_KEYS)
        if "random_runs" in experiment:
            if "label" not in experiment:
                _fail(path, where + ".label", "required")
            tasks += _random_run_tasks(path, where, experiment, registry, scene_dir, study)
            continue
        for key in ("label", "integrators"):
            if key not in experiment:
                _fail(path, "%s.%s" % (where, key), "required")
        if ("scenes" in experiment) == ("random_scenes" in experiment):
            _fail(path, where + ".scenes", "give exactly one of 'scenes' and 'random_scenes'")
        randoms = [None]
        if "random_scenes" in experiment:
            family = experiment["random_scenes"]
            _check_keys(path, where + ".random_scenes", family, RANDOM_KEYS)
            for key in ("seed", "count"):
                value = family.get(key)
                if isinstance(value, bool) or not isinstance(value, int) or value < (1 if key == "count" else 0):
                    _fail(path, "%s.random_scenes.%s" % (where, key), "must be a whole number %s, got %r"
                          % ("≥ 1" if key == "count" else "≥ 0", value))
            first = family.get("first", 0)
            if isinstance(first, bool) or not isinstance(first, int) or first < 0:
                _fail(path, where + ".random_scenes.first", "must be a whole number ≥ 0, got %r" % (first,))
            scenes = [resolve_scene(path, where + ".random_scenes.base", family.get("base", "free_coast"), scene_dir)]
            randoms = ["%d:%d" % (family["seed"], k) for k in range(first, first + family["count"])]
        else:
            scenes = [resolve_scene(path, "%s.scenes" % where, s, scene_dir)
                      for s in _string_list(path, where + ".scenes", experiment["scenes"])]
        methods = _string_list(path, where + ".integrators", experiment["integrators"], registry.names)
        steps = _positive_list(path, where + ".steps", experiment["steps"]) if "steps" in experiment else [None]
        tolerances = (_positive_list(path, where + ".tolerances", experiment["tolerances"])
                      if "tolerances" in experiment else [None])
        durations = (_positive_list(path, where + ".durations", experiment["durations"])
                     if "durations" in experiment else [None])
        rates = (_positive_list(path, where + ".output_rates", experiment["output_rates"])
                 if "output_rates" in experiment else [None])
        forms = (_string_list(path, where + ".birkhoffian_forms", experiment["birkhoffian_forms"], registry.forms)
                 if "birkhoffian_forms" in experiment else [None])
        control = experiment.get("step_control", "fixed")
        if control not in registry.step_controls:
            _fail(path, where + ".step_control", "must be %s, got %r" % (" or ".join(registry.step_controls), control))
        if control == "reversible" and tolerances == [None]:
            _fail(path, where + ".tolerances", "required with step_control: reversible")
        expect = experiment.get("expect", "finish")
        if expect not in ("finish", "finish_or_refuse"):
            _fail(path, where + ".expect", "must be finish or finish_or_refuse, got %r" % (expect,))
        end_only = experiment.get("end_only", False)
        if not isinstance(end_only, bool):
            _fail(path, where + ".end_only", "must be true or false, got %r" % (end_only,))
        reference = experiment.get("reference")
        if reference is not None:
            _check_keys(path, where + ".reference", reference, CLI_REFERENCE_KEYS)
            if reference.get("integrator") not in registry.names:
                _fail(path, where + ".reference.integrator", "unknown integrator %r" % (reference.get("integrator"),))
            reference_step = _positive(path, where + ".reference.step", reference.get("step"))
            if randoms != [None]:
                _fail(path, where + ".reference", "not with random_scenes")
        for scene_file, random in [(f, r) for f in scenes for r in randoms]:
            scene_text = open(scene_file).read()
            scene_duration = None
            if end_only or reference is not None:
                try:
                    scene_duration = float(yaml.safe_load(scene_text)["duration"])
                except (KeyError, TypeError, ValueError, yaml.YAMLError):
                    _fail(path, where + ".scenes", "scene %s has no duration to end on" % os.path.basename(scene_file))
            if reference is not None:
                # The same member at a step and at half of it, both landing on the end: the runs are
                # judged against the finer one, and the two must agree 10× tighter than a verdict.
                count = max(1, round(scene_duration / reference_step))
                for role, h in (("reference", scene_duration / count), ("reference_check", scene_duration / count / 2)):
                    tasks.append({"type": "simulate", "study": study["name"], "label": experiment["label"],
                                  "scene": os.path.basename(scene_file), "scene_text": scene_text,
                                  "method": reference["integrator"], "step_control": "fixed", "expect": "finish",
                                  "time_limit": study["time_limit"], "role": role, "step": h,
                                  "output_rate": 1.0 / scene_duration})
            for method in methods:
                for h in steps:
                    for tol in tolerances:
                        for duration in durations:
                            for rate in rates:
                                for form in forms:
                                    task = {"type": "simulate", "study": study["name"], "label": experiment["label"],
                                            "scene": os.path.basename(scene_file), "scene_text": scene_text,
                                            "method": method, "step_control": control, "expect": expect,
                                            "time_limit": study["time_limit"]}
                                    if end_only:  # one output step: the end
                                        h, rate = scene_duration, 1.0 / scene_duration
                                    for key, value in (("step", h), ("tolerance", tol), ("duration", duration),
                                                       ("output_rate", rate), ("birkhoffian_form", form),
                                                       ("random_scene", random)):
                                        if value is not None:
                                            task[key] = value
                                    if reference is not None:
                                        task["judged_against_reference"] = True
                                    tasks.append(task)
    return tasks

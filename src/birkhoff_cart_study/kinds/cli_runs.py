"""The cli_runs study kind: runs of the batch CLI, cart_simulate, one task each.

An experiment is either a product of settings (scenes × integrators × steps × tolerances ×
durations × output rates × Birkhoffian forms), optionally judged against a reference run of each
scene, or `random_runs`: seeded random runs that probe the CLI's contract (cli_contract.py). A run
is ok when it ends with exit 0 and a sound CSV; with `expect: finish_or_refuse` a refusal by name
(exit 2–5) counts as an outcome, not a failure.

With a `reference` (a member at about a step and at half of it, both landing on the scene's end),
each run's final position error is divided by its tolerance; a tolerance the two reference runs do
not resolve (they differ by more than a tenth of it) gets no verdict: "unresolved"."""
import math
import os

from .. import schema as s
from .. import scenes
from ..cli_contract import random_runs, with_start_time
from ..references import RESOLUTION, describe_unresolved
from ..tasks import StudyKind, Task, TaskKind
from . import simulate

KIND = StudyKind.CLI_RUNS
SMOKE_RUNS = 40    # --smoke: random runs per experiment at most
SMOKE_VALUES = 2   # --smoke: the first and the last value of each list of a product
SWEEPS = ("steps", "tolerances", "durations", "output_rates", "birkhoffian_forms")  # the product's lists
SETTING_OF = {"steps": "step", "tolerances": "tolerance", "durations": "duration", "output_rates": "output_rate",
              "birkhoffian_forms": "birkhoffian_form"}


def schema(registry):
    integrators = s.name_list(registry.names, "integrator")
    product = s.strict_map({
        "label": s.name("a label"), "scenes": s.scene_list(), "integrators": integrators,
        "steps": s.positive_list(), "tolerances": s.positive_list(1.0), "durations": s.positive_list(1e7),
        "output_rates": s.positive_list(), "birkhoffian_forms": s.name_list(registry.forms, "Birkhoffian form"),
        "step_control": s.names_of(registry.step_controls, "step control"), "end_only": {"type": "boolean"},
        "reference": s.strict_map({"integrator": s.names_of(registry.names, "integrator"), "step": s.positive()},
                                  ("integrator", "step")),
        "expect": s.EXPECT}, ("label", "scenes", "integrators"))
    random = s.strict_map({
        "label": s.name("a label"), "integrators": integrators,
        "random_runs": s.strict_map({"seed": s.SEED, "count": s.COUNT, "scenes": s.scene_list()}, ("seed", "count"))},
        ("label", "random_runs"))
    experiment = {"if": {"type": "object", "required": ["random_runs"]}, "then": random, "else": product}
    return s.study(KIND.value, experiment)


def smoke(doc):
    """The study at smoke size: at most SMOKE_RUNS random runs, and the first and last value of each
    list of a product."""
    for experiment in doc["experiments"]:
        if "random_runs" in experiment:
            experiment["random_runs"]["count"] = min(experiment["random_runs"]["count"], SMOKE_RUNS)
            continue
        for key in ("scenes",) + SWEEPS:
            values = experiment.get(key)
            if values and len(values) > SMOKE_VALUES:
                experiment[key] = [values[0], values[-1]]
    return doc


def _size(experiment):
    if "random_runs" in experiment:
        return experiment["random_runs"]["count"]
    count = len(experiment["scenes"]) * len(experiment["integrators"])
    for key in SWEEPS:
        count *= len(experiment.get(key) or [None])
    return count + (2 * len(experiment["scenes"]) if "reference" in experiment else 0)


def expand(path, doc, context):
    """The tasks of every experiment; refusals name the key. `context`: registry, scene_dir."""
    s.cap_tasks(path, [_size(experiment) for experiment in doc["experiments"]])
    s.unique_labels(path, doc["experiments"])
    tasks = []
    for i, experiment in enumerate(doc["experiments"]):
        where = ("experiments", i)
        make = _random_run_tasks if "random_runs" in experiment else _product_tasks
        tasks += make(path, where, experiment, doc, context)
    return tasks


def _task(doc, experiment, scene_file, scene_text, settings):
    return Task(TaskKind.SIMULATE, KIND, doc["name"], experiment["label"], os.path.basename(scene_file), scene_text,
                doc.get("time_limit", 3600.0), settings)


def _random_run_tasks(path, where, experiment, doc, context):
    """The seeded random runs of the CLI contract (cli_contract.random_runs): random scenes, start
    times, durations, steps, output rates, integrators, tolerances and forms."""
    registry, scene_dir = context["registry"], context["scene_dir"]
    family = experiment["random_runs"]
    names = family.get("scenes") or scenes.shipped_scene_names(scene_dir)
    files, texts = {}, {}
    for j, name in enumerate(names):
        parts = where + ("random_runs", "scenes", j)
        files[name] = scenes.resolve(path, parts, name, scene_dir)
        texts[name] = scenes.text_of(path, parts, files[name])
        if with_start_time(texts[name], 0.0) is None:
            s.refuse(path, parts, "scene %s has no initial_state time line to move" % name)
    methods = experiment.get("integrators") or registry.names
    tasks = []
    for index, run in enumerate(random_runs(family["seed"], family["count"], sorted(files), methods,
                                            registry.adaptive, list(registry.forms))):
        scene = run.pop("scene")
        settings = dict(run, index=index, step_control="fixed", expect="finish_or_refuse")
        tasks.append(_task(doc, experiment, files[scene], texts[scene], settings))
    return tasks


def _product_tasks(path, where, experiment, doc, context):
    registry, scene_dir = context["registry"], context["scene_dir"]
    control = experiment.get("step_control", "fixed")
    if control != "fixed":
        if "tolerances" not in experiment:
            s.refuse(path, where + ("tolerances",), "required with step_control: %s (the position errors [m])" % control)
        takes = (lambda m: m.reversible) if control == "reversible" else (lambda m: m.adaptive)
        for j, name in enumerate(experiment["integrators"]):
            if not takes(registry.member(name)):
                s.refuse(path, where + ("integrators", j), "%s does not take step_control %s (those that do: %s)"
                         % (name, control, ", ".join(m.name for m in registry.members if takes(m))))
    reference = experiment.get("reference")
    end_only = experiment.get("end_only", False)
    tasks = []
    for j, scene in enumerate(experiment["scenes"]):
        parts = where + ("scenes", j)
        scene_file = scenes.resolve(path, parts, scene, scene_dir)
        text = scenes.text_of(path, parts, scene_file)
        duration = scenes.duration_of(path, parts, scene_file) if end_only or reference else None
        if reference:
            # The same member at a step and at half of it, both landing on the end: the runs are
            # judged against the finer one, and the two must agree to a tenth of a tolerance.
            if reference["step"] > duration:
                s.refuse(path, where + ("reference", "step"), "longer than scene %s's duration %g s"
                         % (os.path.basename(scene_file), duration))
            count = max(1, round(duration / reference["step"]))
            for role, h in (("reference", duration / count), ("reference_check", duration / count / 2)):
                tasks.append(_task(doc, experiment, scene_file, text, {
                    "method": reference["integrator"], "step_control": "fixed", "expect": "finish", "role": role,
                    "step": h, "output_rate": 1.0 / duration}))
        for method in experiment["integrators"]:
            combinations = [{}]
            for key in SWEEPS:
                if key in experiment:
                    combinations = [dict(c, **{SETTING_OF[key]: v if isinstance(v, str) else float(v)})
                                    for c in combinations for v in experiment[key]]
            for combination in combinations:
                settings = dict(combination, method=method, step_control=control,
                                expect=experiment.get("expect", "finish"))
                if end_only:  # one output step: the end
                    settings.update(step=duration, output_rate=1.0 / duration)
                if reference:
                    settings["judged_against_reference"] = True
                tasks.append(_task(doc, experiment, scene_file, text, settings))
    return tasks


wire = simulate.wire
outcome = simulate.outcome
run = simulate.run


def _distance(a, b):
    return math.hypot(a["result"]["x"] - b["result"]["x"], a["result"]["y"] - b["result"]["y"])


def _ok(row):
    return row is not None and row.get("outcome") == "ok" and (row.get("result") or {}).get("x") is not None


def reference_tables(rows):
    """(markdown lines, unresolved): per experiment and scene judged against its reference, the final
    position error / tolerance of each member and tolerance; 'unresolved' (no ratio, no verdict)
    where the reference and its check differ by more than a tenth of the tolerance."""
    simulate_rows = [r for r in rows if r.get("type") == "simulate"]
    judged = [r for r in simulate_rows if r.get("judged_against_reference")]
    out, unresolved = [], []
    within = total = 0
    worst = 0.0
    for label, scene in sorted({(r.get("label"), r.get("scene")) for r in judged}):
        refs = {r.get("role"): r for r in simulate_rows if r.get("label") == label and r.get("scene") == scene
                and r.get("role")}
        ref, check = refs.get("reference"), refs.get("reference_check")
        runs = [r for r in judged if r.get("label") == label and r.get("scene") == scene]
        tolerances = sorted({r["tolerance"] for r in runs if "tolerance" in r}, reverse=True)
        if not (_ok(ref) and _ok(check)):
            reason = "%s %s: the reference run failed" % (label, scene)
            out += ["**%s, %s**: the reference failed: no verdict." % (label, scene), ""]
            unresolved.append(reason)
            continue
        spread = _distance(ref, check)
        out += ["**%s, %s**: reference %s at h = %.3g s and h/2 agree %s." % (
                    label, scene, ref.get("method"), check["step"] * 2,
                    "to %.2g m: it resolves tolerances ≥ %.2g m" % (spread, RESOLUTION * spread) if spread > 0
                    else "to the last digit: it resolves every tolerance"), "",
                "| member | " + " | ".join("%g" % t for t in tolerances) + " |", "|---|" + "---|" * len(tolerances)]
        for method in sorted({str(r.get("method")) for r in runs}):
            cells = []
            for t in tolerances:
                run = next((r for r in runs if str(r.get("method")) == method and r.get("tolerance") == t), None)
                if run is None or not _ok(run):
                    cells.append(str(run.get("outcome", "failed")) if run else "—")
                    continue
                if RESOLUTION * spread > t:
                    cells.append("unresolved")
                    unresolved.append(describe_unresolved("%s %s %s at tolerance %g m" % (label, scene, method, t),
                                                          spread, t))
                    continue
                ratio = _distance(run, check) / t
                total += 1
                within += ratio <= 10.0
                worst = max(worst, ratio)
                rhs = run["result"].get("rhs_evaluations")
                cells.append("%.2g (%s rhs)" % (ratio, rhs if rhs is not None else "?"))
            out.append("| `%s` | %s |" % (method, " | ".join(cells)))
        out.append("")
    if not out:
        return [], []
    head = ["## Against the reference", "",
            "Final position error / tolerance (and rhs evaluations): %d of %d judged runs within 10× of the tolerance, "
            "worst %.3g; %d without a verdict ('unresolved': the reference and its check differ by more than a "
            "tenth of that tolerance)." % (within, total, worst, len(unresolved)), ""]
    return head + out, unresolved


def report(study, rows, directory, stem):
    """The kind's sections of the results page: (markdown lines, unresolved goals)."""
    tables, unresolved = reference_tables(rows)
    return simulate.outcome_tables(rows) + tables, unresolved

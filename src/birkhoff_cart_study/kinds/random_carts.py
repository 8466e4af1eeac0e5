"""The random_carts study kind: cart_simulate on random valid carts of the seeded family
(`--random-scene SEED:K`, docs/accuracy.md §3), each with every integrator of the experiment.

An experiment names its family (`random_scenes: {seed, count, first, base}`: carts first ...
first + count − 1 on the base scene) and its integrators. A cart ends finite with the accuracy
guard's verdict, or (with `expect: finish_or_refuse`, the default) is refused by name."""
from .. import schema as s
from .. import scenes
from ..tasks import StudyKind, Task, TaskKind
from . import simulate

KIND = StudyKind.RANDOM_CARTS
SMOKE_CARTS = 10  # --smoke: carts per experiment at most


def schema(registry):
    experiment = s.strict_map({
        "label": s.name("a label"),
        "random_scenes": s.strict_map({"seed": s.SEED, "count": s.COUNT, "first": s.whole(0, 2 ** 63 - 1),
                                       "base": s.SCENE}, ("seed", "count")),
        "integrators": s.name_list(registry.names, "integrator"),
        "expect": s.EXPECT}, ("label", "random_scenes", "integrators"))
    return s.study(KIND.value, experiment)


def smoke(doc):
    """The study at smoke size: at most SMOKE_CARTS carts per experiment."""
    for experiment in doc["experiments"]:
        family = experiment["random_scenes"]
        family["count"] = min(family["count"], SMOKE_CARTS)
    return doc


def expand(path, doc, context):
    """Every cart of every experiment with each of its integrators; refusals name the key."""
    s.cap_tasks(path, [e["random_scenes"]["count"] * len(e["integrators"]) for e in doc["experiments"]])
    s.unique_labels(path, doc["experiments"])
    tasks = []
    for i, experiment in enumerate(doc["experiments"]):
        where = ("experiments", i)
        family = experiment["random_scenes"]
        parts = where + ("random_scenes", "base")
        base = scenes.resolve(path, parts, family.get("base", "free_coast"), context["scene_dir"])
        text = scenes.text_of(path, parts, base)
        first = family.get("first", 0)
        for k in range(first, first + family["count"]):
            for method in experiment["integrators"]:
                settings = {"method": method, "step_control": "fixed", "random_scene": "%d:%d" % (family["seed"], k),
                            "expect": experiment.get("expect", "finish_or_refuse")}
                tasks.append(Task(TaskKind.SIMULATE, KIND, doc["name"], experiment["label"],
                                  base.rsplit("/", 1)[-1], text, doc.get("time_limit", 3600.0), settings))
    return tasks


wire = simulate.wire
outcome = simulate.outcome
run = simulate.run


def report(study, rows, directory, stem):
    """The kind's sections of the results page: (markdown lines, unresolved goals: none here)."""
    return simulate.outcome_tables(rows), []

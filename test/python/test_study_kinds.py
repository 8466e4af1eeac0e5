"""Each study kind's expansion into tasks (dataclasses with an enum kind), its smoke size, its
command line, and the one table of per-method settings of the work_precision kind."""
import glob
import os

import pytest

from birkhoff_cart_study import kinds
from birkhoff_cart_study.cli_contract import with_start_time
from birkhoff_cart_study.kinds import work_precision, work_precision_report
from birkhoff_cart_study.study import load_study
from birkhoff_cart_study.tasks import StudyKind, Task, TaskKind
from conftest import REPOSITORY, SCENE_DIR
from test_study_schema import CLI_RUNS, RANDOM_CARTS, WORK_PRECISION

SHIPPED = sorted(glob.glob(os.path.join(REPOSITORY, "bench", "studies", "*.yaml")) +
                 glob.glob(os.path.join(REPOSITORY, "checks", "studies", "*.yaml")))


def by_kind(tasks):
    out = {}
    for task in tasks:
        out.setdefault(task.kind, []).append(task)
    return out


def test_the_kinds_table_has_one_module_per_kind():
    assert set(kinds.KINDS) == set(StudyKind)
    for kind, module in kinds.KINDS.items():
        assert module.KIND is kind
        for function in ("schema", "smoke", "expand", "wire", "run", "outcome", "report"):
            assert callable(getattr(module, function)), (kind, function)


def test_work_precision_expands_references_their_checks_and_every_setting(registry, study_file):
    study, tasks = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR)
    assert all(isinstance(t, Task) and isinstance(t.kind, TaskKind) and t.study_kind is StudyKind.WORK_PRECISION
               for t in tasks)
    groups = by_kind(tasks)
    assert [t.label for t in groups[TaskKind.REFERENCE]] == ["whirl"]
    assert [t.settings["check"] for t in groups[TaskKind.REFERENCE_CHECK]] == ["long_double_bulirsch_stoer_tol_1e-18"]
    measures = {(t.settings["method"], t.settings.get("step"), t.settings.get("tolerance"), t.settings.get("simulator_step"))
                for t in groups[TaskKind.MEASURE]}
    assert measures == {("birkhoff_gauss4", 0.02, None, None), ("birkhoff_gauss4", 0.01, None, None),
                        ("dopri5", None, 1e-8, 0.1), ("dopri5", None, 1e-8, 10.0), ("odeint_rkf78", None, 1e-9, None),
                        ("rk2", 0.001, None, None)}
    paper = [t for t in groups[TaskKind.MEASURE] if t.label == "paper"][0]
    assert paper.settings["analytic"] and paper.settings["checkpoints"] == [1.5]
    assert study["labels"] == ["whirl_30s", "paper"]


def test_task_ids_are_stable_and_follow_the_scene_text(registry, study_file):
    _, first = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR)
    _, again = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR)
    assert [t.id for t in first] == [t.id for t in again]
    assert len({t.id for t in first}) == len(first)
    moved = Task(first[0].kind, first[0].study_kind, first[0].study, first[0].label, first[0].scene,
                 first[0].scene_text + "\n# edited\n", first[0].time_limit, dict(first[0].settings))
    from birkhoff_cart_study.tasks import task_id
    assert task_id(moved) != first[0].id


def test_work_precision_wire_runs_the_measurement_with_its_settings(registry, study_file):
    _, tasks = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR)
    dopri5 = [t for t in tasks if t.settings.get("method") == "dopri5" and t.settings.get("simulator_step") == 10.0][0]
    wire = work_precision.wire(dopri5, "/opt/bin")
    argv = wire["argv"]
    assert argv[0] == "/opt/bin/work_precision" and "--measure" in argv
    assert argv[argv.index("--tolerance") + 1] == "1e-08" and argv[argv.index("--simulator-step") + 1] == "10.0"
    assert argv[argv.index("--reference-file") + 1] == "reference.csv" and wire["needs_reference"]
    assert wire["files"] == {"jackknife_whirl.yaml": dopri5.scene_text}
    check = [t for t in tasks if t.kind is TaskKind.REFERENCE_CHECK][0]
    assert work_precision.wire(check, "/b")["argv"][-1] == "--check-setting"


def test_a_new_per_method_setting_is_one_line_of_the_table(registry, study_file, monkeypatch):
    """What the work–precision benchmark's next setting needs: one RunSetting in RUN_SETTINGS; the
    schema, the expansion, the command line and the report's setting text follow."""
    settings = dict(work_precision.RUN_SETTINGS)
    settings["position_tolerances"] = work_precision.RunSetting(
        "position_tolerance", "--position-tolerance", "pos tol", True, lambda m: m.reversible, "the reversible members")
    monkeypatch.setattr(work_precision, "RUN_SETTINGS", settings)
    text = WORK_PRECISION.replace("birkhoff_gauss4: {steps: [0.02, 0.01]}",
                                  "birkhoff_gauss4: {steps: [0.02], position_tolerances: [1.0e-6, 1.0e-8]}")
    _, tasks = load_study(study_file(text), registry, SCENE_DIR)
    gauss4 = [t for t in tasks if t.settings.get("method") == "birkhoff_gauss4"]
    pairs = [(t.settings.get("step"), t.settings.get("position_tolerance")) for t in gauss4]
    assert sorted(pairs, key=str) == sorted([(0.02, None), (None, 1e-6), (None, 1e-8)], key=str)
    argv = work_precision.wire([t for t in gauss4 if t.settings.get("position_tolerance") == 1e-8][0], "/b")["argv"]
    assert argv[argv.index("--position-tolerance") + 1] == "1e-08" and "--step" not in argv
    assert work_precision_report.setting_text({"position_tolerance": 1e-8}, settings) == "pos tol=1e-08"
    refused = WORK_PRECISION.replace("rk2: {steps: [0.001]}", "rk2: {position_tolerances: [1.0e-6]}")
    with pytest.raises(ValueError, match="rk2 does not take position_tolerances"):
        load_study(study_file(refused, "refused.yaml"), registry, SCENE_DIR)


def test_work_precision_smoke_runs_each_method_once_on_a_short_horizon(registry, study_file):
    _, tasks = load_study(study_file(WORK_PRECISION), registry, SCENE_DIR, smoke=True)
    measures = [t for t in tasks if t.kind is TaskKind.MEASURE]
    assert sorted(t.settings["method"] for t in measures) == ["birkhoff_gauss4", "dopri5", "odeint_rkf78", "rk2"]
    assert all(t.settings["repetitions"] == 1 for t in measures)
    assert all(t.settings["duration"] <= work_precision.SMOKE_DURATION for t in tasks)
    gauss4 = [t for t in measures if t.settings["method"] == "birkhoff_gauss4"][0]
    assert gauss4.settings["step"] == 0.02 and gauss4.settings["checkpoints"] == [10.0]


def test_cli_runs_expand_the_product_its_reference_and_random_runs(registry, study_file):
    _, tasks = load_study(study_file(CLI_RUNS), registry, SCENE_DIR)
    sweep = [t for t in tasks if t.label == "sweep"]
    references = [t for t in sweep if t.settings.get("role")]
    judged = [t for t in sweep if t.settings.get("judged_against_reference")]
    assert len(references) == 4 and len(judged) == 8  # 2 scenes × (2 reference runs; 2 members × 2 tolerances)
    free = [t for t in references if t.scene == "free_coast.yaml"]
    assert sorted(t.settings["step"] for t in free) == [0.001, 0.002]
    one = judged[0]
    assert one.settings["step"] == one.settings["output_rate"] ** -1  # end_only: one output step
    argv = kinds.cli_runs.wire(one, "/b")["argv"]
    assert argv[argv.index("--step-control") + 1] == "reversible" and "--position-tolerance" in argv
    reference_argv = kinds.cli_runs.wire(free[0], "/b")["argv"]  # a scene may set its own control
    assert reference_argv[reference_argv.index("--step-control") + 1] == "fixed"
    random = [t for t in tasks if t.label == "random"]
    assert len(random) == 5 and all(t.settings["expect"] == "finish_or_refuse" for t in random)
    wire = kinds.cli_runs.wire(random[0], "/b")
    assert wire["files"][random[0].scene] == with_start_time(random[0].scene_text, random[0].settings["start_time"])


def test_cli_runs_smoke_keeps_the_ends_of_each_list(registry, study_file):
    text = CLI_RUNS.replace("[1.0e-4, 1.0e-6]", "[1.0e-4, 1.0e-5, 1.0e-6, 1.0e-7]").replace("count: 5", "count: 500")
    _, tasks = load_study(study_file(text), registry, SCENE_DIR, smoke=True)
    judged = [t for t in tasks if t.settings.get("judged_against_reference")]
    assert sorted({t.settings["tolerance"] for t in judged}) == [1e-7, 1e-4]
    assert len([t for t in tasks if t.label == "random"]) == kinds.cli_runs.SMOKE_RUNS


def test_random_carts_expand_every_cart_with_every_integrator(registry, study_file):
    _, tasks = load_study(study_file(RANDOM_CARTS), registry, SCENE_DIR)
    assert [(t.settings["random_scene"], t.settings["method"]) for t in tasks] == [
        ("1:0", "rk4"), ("1:0", "birkhoff2"), ("1:1", "rk4"), ("1:1", "birkhoff2"), ("1:2", "rk4"), ("1:2", "birkhoff2")]
    argv = kinds.random_carts.wire(tasks[0], "/b")["argv"]
    assert argv[argv.index("--random-scene") + 1] == "1:0"
    _, smoke = load_study(study_file(RANDOM_CARTS.replace("count: 3", "count: 1000")), registry, SCENE_DIR, smoke=True)
    assert len(smoke) == 2 * kinds.random_carts.SMOKE_CARTS


@pytest.mark.parametrize("path", SHIPPED, ids=[os.path.basename(p) for p in SHIPPED])
def test_every_shipped_study_passes_its_schema_at_full_and_smoke_size(path, registry):
    _, full = load_study(path, registry, SCENE_DIR)
    _, smoke = load_study(path, registry, SCENE_DIR, smoke=True)
    assert 0 < len(smoke) <= min(len(full), 120)

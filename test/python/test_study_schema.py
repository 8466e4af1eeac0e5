"""Study files checked before anything runs: every malformed file below is refused by the runner's
command (exit 2) with one line naming the key, before a task runs or the output directory exists
(the stand-in executables record any run). The valid files of each kind pass."""
import os
import time

import pytest

from birkhoff_cart_study import cli
from birkhoff_cart_study.limits import MAX_FILE_BYTES, StudyError
from birkhoff_cart_study.study import load_study
from conftest import SCENE_DIR

WORK_PRECISION = """
name: unit_study
kind: work_precision
repetitions: 1
time_limit: 60
references:
  whirl: {scene: jackknife_whirl, duration: 30, kind: extended_precision, checkpoints: [10, 30]}
  paper: {kind: analytic}
experiments:
  - label: whirl_30s
    scene: jackknife_whirl
    duration: 30
    reference: whirl
    checkpoints: [10, 30]
    runs:
      birkhoff_gauss4: {steps: [0.02, 0.01]}
      dopri5: {tolerances: [1.0e-8], simulator_steps: [0.1, 10]}
      odeint_rkf78: {tolerances: [1.0e-9]}
  - label: paper
    scene: paper_special
    duration: 1.5
    reference: paper
    runs:
      rk2: {steps: [0.001]}
"""

CLI_RUNS = """
name: unit_cli
kind: cli_runs
time_limit: 60
experiments:
  - label: sweep
    scenes: [free_coast, jackknife_whirl]
    integrators: [birkhoff_gauss4, birkhoff_gauss8]
    step_control: reversible
    tolerances: [1.0e-4, 1.0e-6]
    end_only: true
    reference: {integrator: birkhoff_gauss8, step: 0.002}
    expect: finish_or_refuse
  - label: random
    random_runs: {seed: 17, count: 5}
"""

RANDOM_CARTS = """
name: unit_carts
kind: random_carts
experiments:
  - label: carts
    random_scenes: {seed: 1, count: 3, base: free_coast}
    integrators: [rk4, birkhoff2]
"""

BOMB = "name: bomb\nkind: work_precision\n" + "".join(
    "l%d: &l%d [%s]\n" % (i, i, ",".join(["*l%d" % (i - 1)] * 9 if i else ['"lol"'] * 9)) for i in range(9)) + \
    "description: [*l8,*l8,*l8,*l8,*l8,*l8,*l8,*l8,*l8]\nexperiments: []\n"


def replaced(base, old, new):
    assert old in base, old
    return base.replace(old, new, 1)


# (what, study text, the text the refusal must hold: the key, and what is wrong)
MALFORMED = [
    ("repetitions as text", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: three"),
     "key 'repetitions': must be a whole number, got 'three'"),
    ("repetitions with a point", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 3.0"),
     "key 'repetitions': must be a whole number, got 3.0"),
    ("repetitions out of range", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 0"),
     "key 'repetitions': must be ≥ 1, got 0"),
    ("negative time limit", replaced(WORK_PRECISION, "time_limit: 60", "time_limit: -5"),
     "key 'time_limit': must be > 0, got -5"),
    ("time limit not a number", replaced(WORK_PRECISION, "time_limit: 60", "time_limit: .nan"),
     "key 'time_limit': must be a finite number > 0 [s], got .nan"),
    ("time limit true", replaced(WORK_PRECISION, "time_limit: 60", "time_limit: true"),
     "key 'time_limit': must be a finite number > 0 [s], got true"),
    ("description a number", replaced(WORK_PRECISION, "time_limit: 60", "time_limit: 60\ndescription: 42"),
     "key 'description': must be text without control characters"),
    ("description with a control character", replaced(WORK_PRECISION, "time_limit: 60",
                                                      'time_limit: 60\ndescription: "bell \\a"'),
     "key 'description': must be text without control characters"),
    ("unknown top-level key", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 1\nrepetition: 2"),
     "key 'repetition': unknown key (did you mean 'repetitions'? known: name"),
    ("unknown run setting", replaced(WORK_PRECISION, "{steps: [0.02, 0.01]}", "{step: [0.02]}"),
     "key 'experiments[0].runs.birkhoff_gauss4.step': unknown key (did you mean 'steps'? known: steps, tolerances"),
    ("unknown integrator", replaced(WORK_PRECISION, "rk2: {steps", "rk9: {steps"),
     "key 'experiments[1].runs.rk9': unknown integrator (did you mean 'rk4'? known: birkhoff2"),
    ("label with a slash", replaced(WORK_PRECISION, "label: paper", "label: a/b"),
     "key 'experiments[1].label': must be a name of letters, digits, '_' and '-'"),
    ("label with a semicolon", replaced(WORK_PRECISION, "label: paper", "label: 'x;rm -rf'"),
     "key 'experiments[1].label': must be a name of letters, digits, '_' and '-' (at most 64, the first a letter "
     "or digit), got 'x;rm -rf'"),
    ("label with a newline", replaced(WORK_PRECISION, "label: paper", 'label: "two\\nlines"'),
     "key 'experiments[1].label': must be a name of letters, digits, '_' and '-' (at most 64, the first a letter "
     "or digit), got 'two\\nlines'"),
    ("label escaping the output directory", replaced(WORK_PRECISION, "label: paper", "label: x/../../escaped"),
     "key 'experiments[1].label': must be a name"),
    ("study name with a path", replaced(WORK_PRECISION, "name: unit_study", "name: ../evil"),
     "key 'name': must be a name"),
    ("no kind", replaced(WORK_PRECISION, "kind: work_precision\n", ""), "key 'kind': required"),
    ("misspelt kind", replaced(WORK_PRECISION, "kind: work_precision", "kind: work_precison"),
     "key 'kind': must be work_precision, cli_runs, random_carts, got 'work_precison' (did you mean 'work_precision'?)"),
    ("the old engine key", replaced(WORK_PRECISION, "kind: work_precision", "engine: work_precision"),
     "key 'engine': 'engine' is now 'kind'"),
    ("a Python tag", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: !!python/object/apply:os.system [ls]"),
     "key 'repetitions': YAML tag '!!python/object/apply:os.system' is not allowed"),
    ("a date", replaced(WORK_PRECISION, "time_limit: 60", "time_limit: 2026-11-27"),
     "key 'time_limit': a date or time is not a study value"),
    ("an empty file", "", "the file is empty"),
    ("a list, not a map", "- name: x\n", "the file must be a map"),
    ("a key given twice", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 1\nrepetitions: 2"),
     "key 'repetitions': given twice"),
    ("a number as a key", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 1\n7: x"),
     "a key must be a name, got '7'"),
    ("a sweep over the list cap", replaced(WORK_PRECISION, "rk2: {steps: [0.001]}",
                                           "rk2: {steps: [%s]}" % ", ".join("%g" % (1e-3 + i * 1e-7) for i in range(1001))),
     "key 'experiments[1].runs.rk2.steps': holds 1001 values, more than the cap of 1000 (limits.MAX_LIST)"),
    ("a product over the task cap", replaced(RANDOM_CARTS, "count: 3", "count: 300000").replace(
        "[rk4, birkhoff2]", "[rk4, birkhoff2, birkhoff4]"),
     "key 'experiments[0]': the study expands to more than 400000 tasks, the cap (limits.MAX_TASKS)"),
    ("a count over the task cap", replaced(CLI_RUNS, "count: 5", "count: 990000"),
     "key 'experiments[1].random_runs.count': must be ≤ 400000, got 990000"),
    ("an alias bomb", BOMB, "more than 20000 values once its YAML aliases are expanded (cap limits.MAX_VALUES)"),
    ("nesting too deep", replaced(WORK_PRECISION, "repetitions: 1", "repetitions: 1\nx: " + "[" * 40 + "]" * 40),
     "nested deeper than the cap of 12 levels"),
    ("an empty sweep", replaced(WORK_PRECISION, "rk2: {steps: [0.001]}", "rk2: {steps: []}"),
     "key 'experiments[1].runs.rk2.steps': must not be empty"),
    ("a zero step", replaced(WORK_PRECISION, "rk2: {steps: [0.001]}", "rk2: {steps: [0.0]}"),
     "key 'experiments[1].runs.rk2.steps[0]': must be > 0, got 0.0"),
    ("a step twice", replaced(WORK_PRECISION, "rk2: {steps: [0.001]}", "rk2: {steps: [0.001, 0.001]}"),
     "key 'experiments[1].runs.rk2.steps': holds 0.001 twice"),
    ("tolerances for a fixed-step member", replaced(WORK_PRECISION, "rk2: {steps: [0.001]}", "rk2: {tolerances: [1.0e-6]}"),
     "key 'experiments[1].runs.rk2.tolerances': rk2 does not take tolerances (they are for the adaptive methods); "
     "it takes steps"),
    ("a simulator step for a peer", replaced(WORK_PRECISION, "odeint_rkf78: {tolerances: [1.0e-9]}",
                                             "odeint_rkf78: {tolerances: [1.0e-9], simulator_steps: [1]}"),
     "key 'experiments[0].runs.odeint_rkf78.simulator_steps': odeint_rkf78 does not take simulator_steps"),
    ("no sweep of its own", replaced(WORK_PRECISION, "dopri5: {tolerances: [1.0e-8], simulator_steps: [0.1, 10]}",
                                     "dopri5: {simulator_steps: [10]}"),
     "key 'experiments[0].runs.dopri5.tolerances': required for dopri5 (give tolerances)"),
    ("an unknown reference", replaced(WORK_PRECISION, "reference: paper\n", "reference: nowhere\n"),
     "key 'experiments[1].reference': no reference named 'nowhere' under 'references'"),
    ("a checkpoint the reference lacks", replaced(WORK_PRECISION, "checkpoints: [10, 30]\n    runs",
                                                  "checkpoints: [5, 30]\n    runs"),
     "key 'experiments[0].checkpoints': reference 'whirl' has no state at 5 s"),
    ("checkpoints out of order", replaced(WORK_PRECISION, "checkpoints: [10, 30]\n    runs",
                                          "checkpoints: [30, 10]\n    runs"),
     "key 'experiments[0].checkpoints': must increase"),
    ("a closed form with a scene", replaced(WORK_PRECISION, "paper: {kind: analytic}",
                                            "paper: {kind: analytic, scene: paper_special}"),
     "key 'references.paper.scene': not with kind analytic"),
    ("a reference without a duration", replaced(WORK_PRECISION, "scene: jackknife_whirl, duration: 30, kind",
                                                "scene: jackknife_whirl, kind"),
     "key 'references.whirl.duration': required"),
    ("an unknown reference kind", replaced(WORK_PRECISION, "kind: extended_precision", "kind: long_double"),
     "key 'references.whirl.kind': must be 'extended_precision', 'dopri5' or 'analytic', got 'long_double'"),
    ("an unknown scene", replaced(WORK_PRECISION, "scene: paper_special", "scene: no_such_scene"),
     "key 'experiments[1].scene': unknown scene 'no_such_scene'"),
    ("a scene name with a semicolon", replaced(WORK_PRECISION, "scene: paper_special", "scene: 'paper;ls'"),
     "key 'experiments[1].scene': must be a shipped scene's name or the path of a scene file"),
    ("a misspelt step control", replaced(CLI_RUNS, "step_control: reversible", "step_control: reversibel"),
     "key 'experiments[0].step_control': must be 'fixed', 'reversible' or 'adaptive', got 'reversibel' "
     "(did you mean 'reversible'?)"),
    ("reversible control for rk4", replaced(CLI_RUNS, "[birkhoff_gauss4, birkhoff_gauss8]", "[birkhoff_gauss4, rk4]"),
     "key 'experiments[0].integrators[1]': rk4 does not take step_control reversible"),
    ("reversible control without tolerances", replaced(CLI_RUNS, "    tolerances: [1.0e-4, 1.0e-6]\n", ""),
     "key 'experiments[0].tolerances': required with step_control: reversible"),
    ("a step list beside random runs", replaced(CLI_RUNS, "random_runs: {seed: 17, count: 5}",
                                                "random_runs: {seed: 17, count: 5}\n    steps: [0.01]"),
     "key 'experiments[1].steps': unknown key"),
    ("a reference step past the scene", replaced(CLI_RUNS, "step: 0.002", "step: 100"),
     "key 'experiments[0].reference.step': longer than scene free_coast.yaml's duration"),
    ("no carts", replaced(RANDOM_CARTS, "count: 3", "count: 0"), "key 'experiments[0].random_scenes.count': must be ≥ 1"),
    ("a negative seed", replaced(RANDOM_CARTS, "seed: 1", "seed: -1"), "key 'experiments[0].random_scenes.seed': must be ≥ 0"),
    ("two experiments with one label", replaced(CLI_RUNS, "label: random", "label: sweep"),
     "key 'experiments[1].label': 'sweep' is the label of an earlier experiment"),
    ("no experiments", replaced(RANDOM_CARTS, "experiments:\n  - label: carts\n    random_scenes: {seed: 1, count: 3, "
                                              "base: free_coast}\n    integrators: [rk4, birkhoff2]\n", "experiments: []\n"),
     "key 'experiments': must not be empty"),
]


@pytest.mark.parametrize("base", [WORK_PRECISION, CLI_RUNS, RANDOM_CARTS], ids=["work_precision", "cli_runs", "random_carts"])
def test_the_valid_study_of_each_kind_passes(base, registry, study_file):
    study, tasks = load_study(study_file(base), registry, SCENE_DIR)
    assert tasks and all(task.id for task in tasks)


@pytest.mark.parametrize("what,text,expected", MALFORMED, ids=[case[0] for case in MALFORMED])
def test_a_malformed_study_is_refused_naming_the_field_before_anything_runs(what, text, expected, study_file,
                                                                           fake_bin_dir, tmp_path, capsys):
    path = study_file(text)
    output = tmp_path / "out"
    start = time.monotonic()
    status = cli.main([path, "--bin-dir", fake_bin_dir, "--output-dir", str(output), "--workers", "1"])
    stderr = capsys.readouterr().err
    assert status == 2, stderr
    assert expected in stderr, stderr
    assert len(stderr.strip().splitlines()) == 1, stderr  # one line
    assert len(stderr) < 600, stderr                      # short, whatever the value
    assert not output.exists()                            # nothing ran, nothing was written
    assert not os.path.exists(os.path.join(fake_bin_dir, "ran"))
    assert time.monotonic() - start < 5.0


def test_a_file_over_the_size_cap_is_refused_unparsed(study_file, registry):
    path = study_file("name: big\n# " + "x" * MAX_FILE_BYTES + "\n")
    with pytest.raises(StudyError, match=r"more than the cap of 262144 \(limits.MAX_FILE_BYTES\)"):
        load_study(path, registry, SCENE_DIR)


def test_every_case_names_a_different_problem():
    assert len(MALFORMED) >= 30
    assert len({what for what, _, _ in MALFORMED}) == len(MALFORMED)


def test_the_pages_count_the_malformed_cases():
    """docs/studies.md and docs/developing.md state how many malformed study files are refused."""
    import pathlib
    import re
    docs = pathlib.Path(__file__).resolve().parents[2] / "docs"
    for page, words in (("studies.md", "malformed study files"), ("developing.md", "malformed files")):
        text = re.sub(r"\s+", " ", (docs / page).read_text())
        assert f"{len(MALFORMED)} {words}" in text, f"docs/{page} does not state '{len(MALFORMED)} {words}'"

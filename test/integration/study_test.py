#!/usr/bin/python3
"""rostest study: the study runner as a user runs it (`scripts/study STUDY.yaml`).

Bad study files are refused by name before anything runs; a small study on the embedded local
cluster writes one complete row per task with the row schema; an interrupted study (rows cut,
a torn last line) resumes with only the missing tasks; the same study on a real dask-scheduler
with two dask-workers on 127.0.0.1, one of them killed with SIGKILL mid-study, ends with every
task's row exactly once and errors identical to the undisturbed run; a task past its time limit
and a crashing process become failed rows without stopping the study; the report written from
the rows afterwards (--report-only) has the same tables as the one written at the end of the run.
No timed assertions: limits only guard against hangs."""
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import rospkg
import rostest

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 300  # [s] of wall time per runner call, only against hangs

ROW_FIELDS = ("task_id", "type", "label", "method", "outcome", "exit_status", "process_cpu_s", "process_wall_s",
              "worker", "host", "load_average_1min", "workers", "result")
RESULT_FIELDS = ("position_error_m", "max_energy_residual_J", "max_p2_residual", "rhs_evaluations",
                 "iterations", "cpu_median_s", "steps")

SMALL_STUDY = """
name: small_test_study
engine: work_precision
repetitions: 1
time_limit: 120
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
      birkhoff_gauss4: {steps: [0.02, 0.01, 0.005]}
      birkhoff_gauss8: {steps: [0.1, 0.05]}
      birkhoff2: {steps: [0.01, 0.005]}
      rk4: {steps: [0.01, 0.005]}
      dopri5: {tolerances: [1.0e-8, 1.0e-10]}
      odeint_rkf78: {tolerances: [1.0e-9, 1.0e-12]}
      odeint_bulirsch_stoer_dense_out: {tolerances: [1.0e-9]}
  - label: paper
    scene: paper_special
    duration: 1.5
    reference: paper
    runs:
      birkhoff2: {steps: [0.001]}
      rk2: {steps: [0.001]}
"""


# Tasks of 0.1–1 s each, so that a worker killed after the first rows dies with work in hand.
CLUSTER_STUDY = """
name: cluster_test_study
engine: work_precision
repetitions: 2
time_limit: 120
references:
  whirl: {scene: jackknife_whirl, duration: 200, kind: extended_precision, checkpoints: [200]}
experiments:
  - label: whirl_200s
    scene: jackknife_whirl
    duration: 200
    reference: whirl
    runs:
      birkhoff_gauss4: {steps: [0.02, 0.01, 0.005, 0.0025]}
      birkhoff2: {steps: [0.01, 0.005, 0.0025]}
      rk4: {steps: [0.01, 0.005, 0.0025]}
      birkhoff_gauss8: {steps: [0.05, 0.025]}
"""


def package_path():
    return rospkg.RosPack().get_path(PACKAGE)


def study_command(*arguments):
    return [sys.executable, os.path.join(package_path(), "scripts", "study")] + list(arguments)


def run_study(*arguments, timeout=RUN_LIMIT):
    return subprocess.run(study_command(*arguments), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          universal_newlines=True, timeout=timeout, stdin=subprocess.DEVNULL)


def read_rows(directory):
    with open(os.path.join(directory, "rows.jsonl")) as f:
        return [json.loads(line) for line in f if line.endswith("\n")]


def errors_by_task(rows):
    return {r["task_id"]: (r["outcome"], (r.get("result") or {}).get("position_error_m"),
                           (r.get("result") or {}).get("max_energy_residual_J")) for r in rows}


def tables_of(page):
    """The page's tables below its header block (the header records when and how it was written)."""
    with open(page) as f:
        text = f.read()
    body = text.split("\n## ", 1)[1] if "\n## " in text else ""
    return [line for line in body.splitlines() if line.startswith("|")]


class StudyRunnerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.mkdtemp(prefix="study_test_")
        cls.study = os.path.join(cls.directory, "small.yaml")
        with open(cls.study, "w") as f:
            f.write(SMALL_STUDY)
        cls.local_dir = os.path.join(cls.directory, "local")
        cls.local = run_study(cls.study, "--output-dir", cls.local_dir, "--workers", "2")

    def write(self, name, text):
        path = os.path.join(self.directory, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def test_bad_study_files_are_refused_by_name_before_anything_runs(self):
        base = SMALL_STUDY
        cases = {
            "unknown scene": (base.replace("scene: paper_special", "scene: no_such_scene"),
                              "experiments[1].scene': unknown scene 'no_such_scene'"),
            "unknown integrator": (base.replace("rk2: {steps", "rk9: {steps"),
                                   "experiments[1].runs.rk9': unknown integrator"),
            "non-positive step": (base.replace("rk2: {steps: [0.001]}", "rk2: {steps: [0.0]}"),
                                  "experiments[1].runs.rk2.steps[0]': must be a finite number > 0, got 0.0"),
            "missing reference": (base.replace("reference: paper\n", "reference: nowhere\n"),
                                  "experiments[1].reference': no reference named 'nowhere'"),
            "unknown key": (base.replace("repetitions: 1", "repetitions: 1\nrepetition: 2"),
                            "key 'repetition': unknown key"),
            "tolerance for a fixed-step method": (base.replace("rk2: {steps: [0.001]}", "rk2: {tolerances: [1.0e-6]}"),
                                                  "experiments[1].runs.rk2.tolerances': rk2 takes steps, not tolerances"),
            "reference without a state at a checkpoint": (base.replace("checkpoints: [10, 30]\n    runs", "checkpoints: [5, 30]\n    runs"),
                                                          "reference 'whirl' has no state at 5 s"),
            "not YAML": ("name: [unclosed", "not valid YAML"),
        }
        for what, (text, expected) in cases.items():
            output_dir = os.path.join(self.directory, "bad")
            result = run_study(self.write("bad.yaml", text), "--output-dir", output_dir, timeout=60)
            self.assertEqual(result.returncode, 2, what + ": " + result.stderr)
            self.assertIn(expected, result.stderr, what)
            self.assertFalse(os.path.exists(output_dir), what + ": something ran")

    def test_local_cluster_writes_one_complete_row_per_task(self):
        self.assertEqual(self.local.returncode, 0, self.local.stderr)
        rows = read_rows(self.local_dir)
        measures = [r for r in rows if r["type"] == "measure"]
        self.assertEqual(len(rows), 18)  # a reference, its check, 14 + 2 measurements
        self.assertEqual(len({r["task_id"] for r in rows}), len(rows))
        for row in measures:
            for field in ROW_FIELDS:
                self.assertIn(field, row, field)
            for field in RESULT_FIELDS:
                self.assertIn(field, row["result"], field)
            self.assertEqual(row["outcome"], "ok", row)
            self.assertEqual(row["workers"], 2)
            self.assertGreater(row["process_cpu_s"], 0.0)
        gauss8 = [r for r in measures if r["method"] == "birkhoff_gauss8" and r["step"] == 0.05][0]
        self.assertLess(gauss8["result"]["position_error_m"], 1e-7)  # eighth order at 50 ms over 30 s
        self.assertIn("study small_test_study: 18 tasks: 18 ok", self.local.stdout)
        self.assertIn("tasks done", self.local.stderr)
        with open(os.path.join(self.local_dir, "results.md")) as f:
            page = f.read()
        for text in ("## whirl_30s", "Best Birkhoffian member against each peer", "`odeint_rkf78`", "machine",
                     "Dask workers"):
            self.assertIn(text, page)
        self.assertTrue(os.path.exists(os.path.join(self.local_dir, "results_whirl_30s.png")))

    def test_an_interrupted_study_resumes_with_only_the_missing_tasks(self):
        directory = os.path.join(self.directory, "resume")
        os.makedirs(directory)
        with open(os.path.join(self.local_dir, "rows.jsonl")) as f:
            lines = f.readlines()
        with open(os.path.join(directory, "rows.jsonl"), "w") as f:
            f.writelines(lines[:6])
            f.write(lines[6][:40])  # a row torn by the interruption: absent, not half there
        result = run_study(self.study, "--output-dir", directory, "--workers", "1")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("18 tasks, 6 already done, 12 to run", result.stderr)
        rows = read_rows(directory)
        self.assertEqual(len(rows), 18)
        self.assertEqual(errors_by_task(rows), errors_by_task(read_rows(self.local_dir)))
        again = run_study(self.study, "--output-dir", directory, "--workers", "1")
        self.assertIn("18 already done, 0 to run", again.stderr)
        self.assertEqual(len(read_rows(directory)), 18)

    def test_sigint_stops_between_rows_and_the_same_command_runs_only_the_missing_tasks(self):
        study = self.write("interrupted.yaml", CLUSTER_STUDY.replace("cluster_test_study", "interrupted_study"))
        directory = os.path.join(self.directory, "interrupted")
        rows_path = os.path.join(directory, "rows.jsonl")
        runner = subprocess.Popen(study_command(study, "--output-dir", directory, "--workers", "1"),
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        deadline = time.monotonic() + RUN_LIMIT
        while time.monotonic() < deadline and runner.poll() is None:
            if os.path.exists(rows_path) and sum(1 for _ in open(rows_path)) >= 3:
                break
            time.sleep(0.05)
        self.assertIsNone(runner.poll(), "the study ended before it could be interrupted")
        runner.send_signal(signal.SIGINT)
        _, stderr = runner.communicate(timeout=60)
        self.assertEqual(runner.returncode, 130, stderr)
        self.assertIn("the same command resumes", stderr)
        done = len(read_rows(directory))
        self.assertLess(done, 14)
        again = run_study(study, "--output-dir", directory, "--workers", "1")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertIn("14 tasks, %d already done, %d to run" % (done, 14 - done), again.stderr)
        rows = read_rows(directory)
        self.assertEqual(sorted(r["task_id"] for r in rows), sorted({r["task_id"] for r in rows}))
        self.assertEqual(len(rows), 14)

    def test_the_report_from_the_rows_equals_the_one_written_at_the_end(self):
        page = os.path.join(self.directory, "from_rows.md")
        result = run_study(self.study, "--output-dir", self.local_dir, "--report-only", "--report", page)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(tables_of(page), tables_of(os.path.join(self.local_dir, "results.md")))
        self.assertTrue(tables_of(page))

    def test_timeouts_and_crashes_become_failed_rows(self):
        text = SMALL_STUDY.replace("time_limit: 120", "time_limit: 1.0").replace(
            "duration: 30\n    reference: whirl", "duration: 30\n    reference: whirl")
        text += """  - label: long_one
    scene: jackknife_whirl
    duration: 30
    reference: whirl
    checkpoints: [10, 30]
    runs:
      birkhoff2: {steps: [0.00001]}
"""
        directory = os.path.join(self.directory, "limits")
        result = run_study(self.write("limits.yaml", text), "--output-dir", directory)
        self.assertEqual(result.returncode, 1, result.stderr)
        rows = read_rows(directory)
        long_one = [r for r in rows if r["label"] == "long_one"][0]
        self.assertEqual(long_one["outcome"], "timeout")
        self.assertIn("time limit of 1 s", long_one["reason"])
        crash = """
name: crash_test_study
engine: cart_simulate
time_limit: 60
experiments:
  - label: bad_step
    scenes: [free_coast]
    integrators: [rk4]
    steps: [7.0]
  - label: fine
    scenes: [free_coast]
    integrators: [rk4, birkhoff_gauss4]
    steps: [0.01]
"""
        directory = os.path.join(self.directory, "crash")
        result = run_study(self.write("crash.yaml", crash), "--output-dir", directory)
        self.assertEqual(result.returncode, 1, result.stderr)
        rows = {r["label"] + r["method"]: r for r in read_rows(directory)}
        self.assertEqual(rows["bad_steprk4"]["outcome"], "failed")
        self.assertEqual(rows["bad_steprk4"]["exit_status"], 3)
        self.assertIn("step", rows["bad_steprk4"]["stderr_tail"])
        self.assertEqual(rows["finerk4"]["outcome"], "ok")
        self.assertAlmostEqual(rows["finebirkhoff_gauss4"]["result"]["t"], 6.0)

    @staticmethod
    def wait_for_workers(address, count):
        from distributed import Client
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(count, timeout=120)

    def test_a_real_scheduler_survives_a_killed_worker(self):
        directory = os.path.join(self.directory, "cluster")
        os.makedirs(directory)
        study = self.write("cluster.yaml", CLUSTER_STUDY)
        undisturbed = run_study(study, "--output-dir", os.path.join(directory, "local"), "--workers", "2")
        self.assertEqual(undisturbed.returncode, 0, undisturbed.stderr)
        scheduler_file = os.path.join(directory, "scheduler.json")
        processes = []
        try:
            processes.append(subprocess.Popen(
                ["dask-scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                 "--scheduler-file", scheduler_file], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                start_new_session=True))
            deadline = time.monotonic() + 60
            while not os.path.exists(scheduler_file) and time.monotonic() < deadline:
                time.sleep(0.2)
            with open(scheduler_file) as f:
                address = json.load(f)["address"]
            for name in ("w1", "w2"):
                processes.append(subprocess.Popen(
                    ["dask-worker", address, "--nthreads", "1", "--nworkers", "1", "--name", name,
                     "--no-dashboard", "--local-directory", directory], stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL, start_new_session=True))
            self.wait_for_workers(address, 2)
            runner = subprocess.Popen(study_command(study, "--output-dir", os.path.join(directory, "out"),
                                                    "--scheduler", address),
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
            rows_path = os.path.join(directory, "out", "rows.jsonl")
            deadline = time.monotonic() + RUN_LIMIT
            while time.monotonic() < deadline and runner.poll() is None:
                if os.path.exists(rows_path) and sum(1 for _ in open(rows_path)) >= 3:
                    break
                time.sleep(0.05)
            self.assertIsNone(runner.poll(), "the study ended before the worker could be killed")
            killed_at = sum(1 for _ in open(rows_path))
            os.killpg(processes[2].pid, signal.SIGKILL)  # worker w2 (its nanny and worker process), mid-study
            stdout, stderr = runner.communicate(timeout=RUN_LIMIT)
            self.assertEqual(runner.returncode, 0, stderr)
            self.assertIn("on 2 Dask worker(s) at tcp://127.0.0.1", stderr)
            rows = read_rows(os.path.join(directory, "out"))
            ids = [r["task_id"] for r in rows]
            self.assertLess(killed_at, 14)
            self.assertEqual(len(ids), 14)  # a reference, its check, 12 measurements: each exactly once
            self.assertEqual(len(set(ids)), 14)
            self.assertEqual({r["worker"] for r in rows[killed_at:]}, {"w1"})  # after the kill, only w1 works
            self.assertEqual(errors_by_task(rows), errors_by_task(read_rows(os.path.join(directory, "local"))))
        finally:
            for process in processes:
                try:
                    os.killpg(process.pid, signal.SIGTERM)
                except ProcessLookupError:
                    pass
            for process in processes:
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(process.pid, signal.SIGKILL)


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "study", StudyRunnerTest)

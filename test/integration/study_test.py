#!/usr/bin/python3
"""rostest study: the study runner as a user runs it (`scripts/study STUDY.yaml`).

Bad study files are refused by name before anything runs; a small study on the embedded local
cluster writes one complete row per task with the row schema; an interrupted study (rows cut,
a torn last line) resumes with only the missing tasks; SIGINT, SIGTERM and SIGKILL of the runner
leave no process and no task directory 2 s later, and the same command resumes; the local cluster
listens on loopback only (ss -ltnp); a reference that cannot resolve its goals gives no verdict and
exit 3; the same study on a real dask-scheduler with two dask-workers on 127.0.0.1, one of them
killed with SIGKILL mid-study, ends with every task's row exactly once, errors identical to the
undisturbed run and nothing left of the killed worker's task; SIGINT and SIGKILL of a runner on
that cluster stop its tasks' processes within a second; a TLS scheduler (certificates made with
openssl) runs a study; a task past its time limit and a crashing process become failed rows; the
report from the rows (--report-only) has the same tables. No timed assertions of speed: limits
only guard against hangs, and the "within a second" of a cancelled task is its contract."""
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rospkg
import rostest

PACKAGE = "birkhoff_cart"
RUN_LIMIT = 300  # [s] of wall time per runner call, only against hangs
SETTLE = 2.0     # [s] after a cancelled or killed runner: nothing of it may be left by then
STOPPED = 1.0    # [s] a cancelled task's process may take to stop

ROW_FIELDS = ("task_id", "type", "label", "method", "outcome", "exit_status", "process_cpu_s", "process_wall_s",
              "worker", "host", "load_average_1min", "workers", "result")
RESULT_FIELDS = ("position_error_m", "max_energy_residual_J", "max_p2_residual", "rhs_evaluations",
                 "iterations", "cpu_median_s", "steps")

SMALL_STUDY = """
name: small_test_study
kind: work_precision
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
kind: work_precision
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

# Tasks of several seconds each (1.5 million steps), so that a runner stopped while they run has
# their processes to stop. Each task's command line holds this study's marker scene.
LONG_TASKS = """
name: long_tasks_%(name)s
kind: work_precision
repetitions: 1
time_limit: 300
references:
  paper: {kind: analytic}
experiments:
  - label: paper
    scene: paper_special
    duration: 1.5
    reference: paper
    runs:
      birkhoff2: {steps: [1.0e-6, 1.1e-6, 1.2e-6, 1.3e-6]}
      rk2: {steps: [1.0e-6, 1.1e-6]}
"""

# The reference of the near-jackknife whirl over 2000 s: long double rkf78 strides over whole
# turns and its check, long double bulirsch_stoer, disagrees with it by hundreds of metres.
UNRESOLVED_STUDY = """
name: near_jackknife_2000s
kind: work_precision
repetitions: 1
time_limit: 600
references:
  near_jackknife: {scene: near_jackknife, duration: 2000, kind: extended_precision, checkpoints: [10, 100, 1000, 2000]}
experiments:
  - label: near_jackknife_2000s
    scene: near_jackknife
    duration: 2000
    reference: near_jackknife
    checkpoints: [10, 100, 1000, 2000]
    runs:
      birkhoff_gauss8: {steps: [0.1, 0.05]}
      odeint_bulirsch_stoer: {tolerances: [1.0e-10]}
      odeint_rkf78: {tolerances: [1.0e-12]}
"""

# A cart_simulate sweep judged against birkhoff2 at 0.1 s and 0.05 s: far too coarse for 1e-9 m.
UNRESOLVED_CLI_STUDY = """
name: unresolved_cli
kind: cli_runs
time_limit: 120
experiments:
  - label: coarse_reference
    scenes: [free_coast]
    integrators: [birkhoff_gauss8]
    step_control: reversible
    tolerances: [1.0e-2, 1.0e-9]
    end_only: true
    reference: {integrator: birkhoff2, step: 0.1}
"""


def package_path():
    return rospkg.RosPack().get_path(PACKAGE)


def study_command(*arguments):
    return [sys.executable, os.path.join(package_path(), "scripts", "study")] + list(arguments)


def tagged_environment(directory):
    """The environment of a runner or worker whose processes (and task directories) are its own:
    TMPDIR set to `directory`, which every process it starts inherits."""
    os.makedirs(directory, exist_ok=True)
    return dict(os.environ, TMPDIR=directory)


def run_study(*arguments, timeout=RUN_LIMIT, tmp=None):
    env = tagged_environment(tmp) if tmp else None
    return subprocess.run(study_command(*arguments), stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                          universal_newlines=True, timeout=timeout, stdin=subprocess.DEVNULL)


def read_rows(directory):
    with open(os.path.join(directory, "rows.jsonl")) as f:
        return [json.loads(line) for line in f if line.endswith("\n")]


def count_rows(directory):
    path = os.path.join(directory, "rows.jsonl")
    return sum(1 for _ in open(path)) if os.path.exists(path) else 0


def errors_by_task(rows):
    return {r["task_id"]: (r["outcome"], (r.get("result") or {}).get("position_error_m"),
                           (r.get("result") or {}).get("max_energy_residual_J")) for r in rows}


def errors_by_setting(rows):
    """errors_by_task keyed by what a task does, for two studies of one content under two names."""
    return errors_by_task([dict(r, task_id=(r["type"], r["label"], r.get("method"), r.get("step"), r.get("tolerance")))
                           for r in rows])


def tables_of(page):
    """The page's tables below its header block (the header records when and how it was written)."""
    with open(page) as f:
        text = f.read()
    body = text.split("\n## ", 1)[1] if "\n## " in text else ""
    return [line for line in body.splitlines() if line.startswith("|")]


def processes_of(tmp, task_only=False):
    """The live processes whose TMPDIR is `tmp` (all of a runner's, or with task_only the tasks'
    engine processes a worker started: not the worker nor its threads' idle supervisors)."""
    marker = ("TMPDIR=%s\0" % tmp).encode()
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            with open("/proc/%s/environ" % pid, "rb") as f:
                if marker not in f.read():
                    continue
            with open("/proc/%s/stat" % pid) as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                    continue
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                command = f.read()
        except OSError:
            continue
        if task_only and not any(name in command for name in (b"work_precision\0", b"cart_simulate\0")):
            continue
        found.append((int(pid), command.replace(b"\0", b" ")[:120].decode(errors="replace")))
    return found


def task_directories(tmp):
    return [name for name in os.listdir(tmp) if name.startswith("birkhoff_cart_task_")] if os.path.isdir(tmp) else []


def wait_until(condition, limit):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def wait_for_task_processes(tmp, count, runner=None):
    """Until `count` work_precision/cart_simulate processes run with TMPDIR `tmp`."""
    def running():
        return len(processes_of(tmp, task_only=True))
    ok = wait_until(lambda: running() >= count or (runner is not None and runner.poll() is not None), RUN_LIMIT)
    return ok and running() >= count


class Cluster:
    """A real dask-scheduler and dask-workers on 127.0.0.1 (each worker with its own TMPDIR), started
    in sessions of their own; `tls`: (ca, cert, key) files for a TLS cluster."""

    def __init__(self, directory, workers=("w1", "w2"), tls=None):
        self.directory = directory
        self.processes = {}
        scheduler_file = os.path.join(directory, "scheduler.json")
        security = ["--tls-ca-file", tls[0], "--tls-cert", tls[1], "--tls-key", tls[2]] if tls else []
        self.processes["scheduler"] = subprocess.Popen(
            ["dask-scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--dashboard-address",
             "127.0.0.1:0", "--scheduler-file", scheduler_file] + (["--protocol", "tls"] if tls else []) + security,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        wait_until(lambda: os.path.exists(scheduler_file) and os.path.getsize(scheduler_file) > 0, 60)
        time.sleep(0.2)
        with open(scheduler_file) as f:
            self.address = json.load(f)["address"]
        self.tmp = {}
        for name in workers:
            self.tmp[name] = os.path.join(directory, "tmp_" + name)
            self.processes[name] = subprocess.Popen(
                ["dask-worker", self.address, "--nthreads", "1", "--nworkers", "1", "--name", name, "--no-dashboard",
                 "--dashboard-address", "127.0.0.1:0", "--host", "127.0.0.1", "--local-directory", directory] + security,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                env=tagged_environment(self.tmp[name]))
        self.security = security
        from distributed import Client
        from distributed.security import Security
        kwargs = {"security": Security(tls_ca_file=tls[0], tls_client_cert=tls[1], tls_client_key=tls[2],
                                       require_encryption=True)} if tls else {}
        with Client(self.address, timeout="60s", **kwargs) as client:
            client.wait_for_workers(len(workers), timeout=120)

    def task_leftovers(self):
        return [p for tmp in self.tmp.values() for p in processes_of(tmp, task_only=True)] + \
            [d for tmp in self.tmp.values() for d in task_directories(tmp)]

    def close(self):
        for process in self.processes.values():
            try:
                os.killpg(process.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for process in self.processes.values():
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


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

    def assertNothingLeft(self, tmp, what):
        self.assertTrue(wait_until(lambda: not processes_of(tmp) and not task_directories(tmp), SETTLE),
                        "%s: left %s and %s" % (what, processes_of(tmp), task_directories(tmp)))

    def test_bad_study_files_are_refused_by_name_before_anything_runs(self):
        base = SMALL_STUDY
        bomb = "name: bomb\nkind: work_precision\n" + "".join(
            "l%d: &l%d [%s]\n" % (i, i, ",".join(["*l%d" % (i - 1)] * 9 if i else ['"lol"'] * 9)) for i in range(9))
        cases = {
            "unknown scene": (base.replace("scene: paper_special", "scene: no_such_scene"),
                              "experiments[1].scene': unknown scene 'no_such_scene'"),
            "unknown integrator": (base.replace("rk2: {steps", "rk9: {steps"),
                                   "experiments[1].runs.rk9': unknown integrator (did you mean"),
            "non-positive step": (base.replace("rk2: {steps: [0.001]}", "rk2: {steps: [0.0]}"),
                                  "experiments[1].runs.rk2.steps[0]': must be > 0, got 0.0"),
            "unknown key": (base.replace("repetitions: 1", "repetitions: 1\nrepetition: 2"),
                            "key 'repetition': unknown key (did you mean 'repetitions'?"),
            "tolerance for a fixed-step method": (base.replace("rk2: {steps: [0.001]}", "rk2: {tolerances: [1.0e-6]}"),
                                                  "experiments[1].runs.rk2.tolerances': rk2 does not take tolerances"),
            "a label that is a path": (base.replace("label: paper", "label: x/../../escaped"),
                                       "experiments[1].label': must be a name"),
            "the alias bomb": (bomb + "description: [*l8,*l8,*l8,*l8,*l8,*l8,*l8,*l8,*l8]\nexperiments: []\n",
                               "(cap limits.MAX_VALUES)"),
            "not YAML": ("name: [unclosed", "not valid YAML"),
        }
        for what, (text, expected) in cases.items():
            output_dir = os.path.join(self.directory, "bad")
            result = run_study(self.write("bad.yaml", text), "--output-dir", output_dir, timeout=60)
            self.assertEqual(result.returncode, 2, what + ": " + result.stderr)
            self.assertIn(expected, result.stderr, what)
            self.assertEqual(len(result.stderr.strip().splitlines()), 1, what + ": " + result.stderr)
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
        check = [r for r in rows if r["type"] == "reference_check"][0]
        self.assertEqual(check["result"]["reference"], "long_double_bulirsch_stoer_tol_1e-18")
        self.assertIn("study small_test_study: 18 tasks: 18 ok", self.local.stdout)
        self.assertNotIn("without a verdict", self.local.stdout)
        self.assertIn("tasks done", self.local.stderr)
        with open(os.path.join(self.local_dir, "results.md")) as f:
            page = f.read()
        for text in ("## whirl_30s", "Best Birkhoffian member against each peer", "`odeint_rkf78`", "machine",
                     "Dask workers", "long_double_rkf78_tol_1e-18 vs long_double_bulirsch_stoer_tol_1e-18"):
            self.assertIn(text, page)
        self.assertNotIn("unresolved", page)
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

    def test_a_stopped_or_killed_runner_leaves_nothing_and_the_same_command_resumes(self):
        """SIGINT (exit 130), SIGTERM (exit 143) and SIGKILL of the runner while its tasks' processes
        run: 2 s later no process and no task directory is left, and the same command resumes."""
        for number, status in ((signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGKILL, -signal.SIGKILL)):
            name = signal.Signals(number).name.lower()
            study = self.write("long_%s.yaml" % name, LONG_TASKS % {"name": name})
            directory = os.path.join(self.directory, "long_" + name)
            tmp = os.path.join(self.directory, "tmp_" + name)
            runner = subprocess.Popen(study_command(study, "--output-dir", directory, "--workers", "2"),
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                                      env=tagged_environment(tmp))
            self.assertTrue(wait_for_task_processes(tmp, 2, runner), name + ": no task ran")
            runner.send_signal(number)
            _, stderr = runner.communicate(timeout=60)
            self.assertEqual(runner.returncode, status, name + ": " + stderr)
            if number != signal.SIGKILL:
                self.assertIn("the same command resumes", stderr)
            self.assertNothingLeft(tmp, name)
            done = count_rows(directory)
            self.assertLess(done, 6, name)
            again = run_study(study, "--output-dir", directory, "--workers", "2", tmp=tmp)
            self.assertEqual(again.returncode, 0, again.stderr)
            self.assertIn("6 tasks, %d already done, %d to run" % (done, 6 - done), again.stderr)
            rows = read_rows(directory)
            self.assertEqual(sorted(r["task_id"] for r in rows), sorted({r["task_id"] for r in rows}))
            self.assertEqual(len(rows), 6)
            self.assertNothingLeft(tmp, name + ", after the resumed run")

    def test_a_local_study_listens_on_loopback_only(self):
        study = self.write("long_listen.yaml", LONG_TASKS % {"name": "listen"})
        tmp = os.path.join(self.directory, "tmp_listen")
        runner = subprocess.Popen(study_command(study, "--output-dir", os.path.join(self.directory, "listen"),
                                                "--workers", "2"), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  env=tagged_environment(tmp))
        try:
            self.assertTrue(wait_for_task_processes(tmp, 2, runner))
            pids = {pid for pid, _ in processes_of(tmp)}
            listing = subprocess.run(["ss", "-ltnpH"], stdout=subprocess.PIPE, universal_newlines=True).stdout
            mine = [line.split()[3] for line in listing.splitlines() if any("pid=%d," % pid in line for pid in pids)]
            self.assertGreaterEqual(len(mine), 4, listing)  # the scheduler and its HTTP server, each worker's
            for address in mine:
                self.assertTrue(address.startswith(("127.0.0.1:", "[::1]:")), "%s listens on %s" % (pids, address))
        finally:
            runner.send_signal(signal.SIGINT)
            runner.wait(timeout=60)
        self.assertNothingLeft(tmp, "the listening study")

    def test_a_reference_that_cannot_resolve_a_goal_gives_no_verdict(self):
        directory = os.path.join(self.directory, "unresolved")
        result = run_study(self.write("unresolved.yaml", UNRESOLVED_STUDY), "--output-dir", directory, "--workers", "2")
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("6 tasks: 6 ok", result.stdout)
        self.assertIn("3 goals without a verdict: the reference does not resolve them (near_jackknife_2000s, "
                      "error ≤ 0.001 m (reference near_jackknife): the reference and its check differ by", result.stdout)
        with open(os.path.join(directory, "results.md")) as f:
            page = f.read()
        self.assertIn("**No verdict for 3 goals", page)
        self.assertIn("| `birkhoff_gauss8` | unresolved | unresolved | unresolved |", page)
        self.assertIn("| *against every peer* | unresolved: no verdict | unresolved: no verdict | unresolved: no verdict |",
                      page)
        rows = read_rows(directory)
        reference = {r["type"]: r for r in rows if r["type"].startswith("reference")}
        self.assertEqual(reference["reference_check"]["result"]["reference"], "long_double_bulirsch_stoer_tol_1e-18")
        directory = os.path.join(self.directory, "unresolved_cli")
        result = run_study(self.write("unresolved_cli.yaml", UNRESOLVED_CLI_STUDY), "--output-dir", directory)
        self.assertEqual(result.returncode, 3, result.stdout + result.stderr)
        self.assertIn("1 goal without a verdict", result.stdout)
        with open(os.path.join(directory, "results.md")) as f:
            page = f.read()
        self.assertRegex(page, r"\| `birkhoff_gauss8` \| [0-9.e-]+ \(\d+ rhs\) \| unresolved \|")

    def test_the_report_from_the_rows_equals_the_one_written_at_the_end(self):
        page = os.path.join(self.directory, "from_rows.md")
        result = run_study(self.study, "--output-dir", self.local_dir, "--report-only", "--report", page)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(tables_of(page), tables_of(os.path.join(self.local_dir, "results.md")))
        self.assertTrue(tables_of(page))

    def test_timeouts_and_crashes_become_failed_rows(self):
        text = SMALL_STUDY.replace("time_limit: 120", "time_limit: 1.0")
        text += """  - label: long_one
    scene: jackknife_whirl
    duration: 30
    reference: whirl
    checkpoints: [10, 30]
    runs:
      birkhoff2: {steps: [0.00001]}
"""
        directory = os.path.join(self.directory, "limits")
        tmp = os.path.join(self.directory, "tmp_limits")
        result = run_study(self.write("limits.yaml", text), "--output-dir", directory, tmp=tmp)
        self.assertEqual(result.returncode, 1, result.stderr)
        rows = read_rows(directory)
        long_one = [r for r in rows if r["label"] == "long_one"][0]
        self.assertEqual(long_one["outcome"], "timeout")
        self.assertIn("time limit of 1 s", long_one["reason"])
        self.assertNothingLeft(tmp, "the timed-out study")
        crash = """
name: crash_test_study
kind: cli_runs
time_limit: 60
experiments:
  - label: bad_step
    scenes: [free_coast]
    integrators: [rk4]
    steps: [7.0]
  - label: fine
    scenes: [free_coast, noisy_odometry, steering_actuator]
    integrators: [rk4, birkhoff_gauss4]
    steps: [0.01]
"""
        directory = os.path.join(self.directory, "crash")
        result = run_study(self.write("crash.yaml", crash), "--output-dir", directory)
        self.assertEqual(result.returncode, 1, result.stderr)
        rows = {r["label"] + r["method"] + r["scene"]: r for r in read_rows(directory)}
        bad = rows["bad_steprk4free_coast.yaml"]
        self.assertEqual(bad["outcome"], "failed")
        self.assertEqual(bad["exit_status"], 3)
        self.assertIn("step", bad["stderr_tail"])
        # The scenes whose CSV has more columns (the odometry sensor's, the actuators') are ok.
        for key in ("finerk4free_coast.yaml", "finerk4noisy_odometry.yaml", "finebirkhoff_gauss4steering_actuator.yaml"):
            self.assertEqual(rows[key]["outcome"], "ok", rows[key])
        self.assertAlmostEqual(rows["finebirkhoff_gauss4free_coast.yaml"]["result"]["t"], 6.0)

    def test_a_real_scheduler_survives_a_killed_worker(self):
        directory = os.path.join(self.directory, "cluster")
        os.makedirs(directory)
        study = self.write("cluster.yaml", CLUSTER_STUDY)
        undisturbed = run_study(study, "--output-dir", os.path.join(directory, "local"), "--workers", "2")
        self.assertEqual(undisturbed.returncode, 0, undisturbed.stderr)
        cluster = Cluster(directory)
        try:
            runner = subprocess.Popen(study_command(study, "--output-dir", os.path.join(directory, "out"),
                                                    "--scheduler", cluster.address),
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
            out = os.path.join(directory, "out")
            self.assertTrue(wait_until(lambda: count_rows(out) >= 3 or runner.poll() is not None, RUN_LIMIT))
            self.assertIsNone(runner.poll(), "the study ended before the worker could be killed")
            killed_at = count_rows(out)
            os.killpg(cluster.processes["w2"].pid, signal.SIGKILL)  # worker w2 (its nanny and worker process), mid-study
            self.assertTrue(wait_until(lambda: not processes_of(cluster.tmp["w2"]), SETTLE),
                            "the killed worker's tasks live on: %s" % processes_of(cluster.tmp["w2"]))
            self.assertEqual(task_directories(cluster.tmp["w2"]), [])
            stdout, stderr = runner.communicate(timeout=RUN_LIMIT)
            self.assertEqual(runner.returncode, 0, stderr)
            self.assertIn("on 2 Dask worker(s) at tcp://127.0.0.1", stderr)
            rows = read_rows(out)
            ids = [r["task_id"] for r in rows]
            self.assertLess(killed_at, 14)
            self.assertEqual(len(ids), 14)  # a reference, its check, 12 measurements: each exactly once
            self.assertEqual(len(set(ids)), 14)
            self.assertEqual({r["worker"] for r in rows[killed_at:]}, {"w1"})  # after the kill, only w1 works
            self.assertEqual(errors_by_task(rows), errors_by_task(read_rows(os.path.join(directory, "local"))))
        finally:
            cluster.close()

    def test_a_runner_stopped_or_killed_on_a_real_cluster_stops_its_tasks(self):
        """On an external cluster the tasks' processes belong to the workers: SIGINT of the runner
        cancels them, SIGKILL drops its client; either way they stop within a second."""
        directory = os.path.join(self.directory, "cluster_stop")
        os.makedirs(directory)
        cluster = Cluster(directory)
        try:
            for number in (signal.SIGINT, signal.SIGKILL):
                name = signal.Signals(number).name.lower()
                study = self.write("cluster_%s.yaml" % name, LONG_TASKS % {"name": "cluster_" + name})
                runner = subprocess.Popen(study_command(study, "--output-dir", os.path.join(directory, name),
                                                        "--scheduler", cluster.address),
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                self.assertTrue(wait_until(lambda: sum(len(processes_of(t, task_only=True)) for t in cluster.tmp.values())
                                           >= 2 or runner.poll() is not None, RUN_LIMIT))  # a task on each worker
                runner.send_signal(number)
                stopped = time.monotonic()
                self.assertTrue(wait_until(lambda: not cluster.task_leftovers(), STOPPED),
                                "%s: left %s" % (name, cluster.task_leftovers()))
                self.assertLess(time.monotonic() - stopped, STOPPED + 0.1)
                runner.wait(timeout=60)
        finally:
            cluster.close()

    def test_a_study_on_a_tls_scheduler(self):
        directory = os.path.join(self.directory, "tls")
        os.makedirs(directory)
        ca, cert, key = (os.path.join(directory, name) for name in ("ca.pem", "study.pem", "study.key"))
        for command in (  # the commands of docs/studies.md, "On a cluster"
                ["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "30", "-subj", "/CN=study CA",
                 "-keyout", os.path.join(directory, "ca.key"), "-out", ca],
                ["openssl", "req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=study", "-keyout", key,
                 "-out", os.path.join(directory, "study.csr")],
                ["openssl", "x509", "-req", "-in", os.path.join(directory, "study.csr"), "-CA", ca, "-CAkey",
                 os.path.join(directory, "ca.key"), "-CAcreateserial", "-days", "30", "-out", cert]):
            subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        cluster = Cluster(directory, workers=("w1",), tls=(ca, cert, key))
        try:
            self.assertTrue(cluster.address.startswith("tls://127.0.0.1:"))
            study = self.write("tls.yaml", SMALL_STUDY.replace("small_test_study", "tls_study"))
            result = run_study(study, "--output-dir", os.path.join(directory, "out"), "--scheduler", cluster.address,
                               "--tls-ca-file", ca, "--tls-cert", cert, "--tls-key", key)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("18 tasks: 18 ok", result.stdout)
            self.assertIn("at tls://127.0.0.1", result.stderr)
            self.assertEqual(errors_by_setting(read_rows(os.path.join(directory, "out"))), errors_by_setting(read_rows(self.local_dir)))
            plain = run_study(study, "--output-dir", os.path.join(directory, "plain"), "--scheduler",
                              cluster.address.replace("tls://", "tcp://"), "--scheduler-timeout", "3")
            self.assertEqual(plain.returncode, 2, plain.stderr)  # a TLS scheduler does not talk to a plain client
        finally:
            cluster.close()


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "study", StudyRunnerTest)

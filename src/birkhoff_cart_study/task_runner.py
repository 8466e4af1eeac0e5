"""One task = one process of the batch engine, run on a Dask worker; returns one row (a dict).

This module is what workers execute: it needs only the standard library and the package's
executables (`bin_dir`, the same path on every worker). The scene travels inside the task, so
workers need no shared file system."""
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import tempfile
import time

from .cli_contract import judge

STDERR_TAIL = 2000  # characters of a failed process's stderr kept in its row


def _worker_name():
    try:
        from distributed import get_worker
        return get_worker().name
    except (ImportError, ValueError):
        return "local"


def run_process(command, time_limit, work_dir):
    """Runs `command` with stdout and stderr to files; returns (exit status, stdout, stderr,
    CPU seconds of the process, wall seconds, timed_out). Past `time_limit` [s] of wall time the
    process group is killed. The CPU time is the child's own (wait4's rusage)."""
    out_path, err_path = os.path.join(work_dir, "stdout"), os.path.join(work_dir, "stderr")
    with open(out_path, "wb") as out, open(err_path, "wb") as err:
        start = time.monotonic()
        process = subprocess.Popen(command, stdout=out, stderr=err, stdin=subprocess.DEVNULL,
                                   start_new_session=True)
        timed_out = False
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > time_limit:
                timed_out = True
                os.killpg(process.pid, signal.SIGKILL)
                pid, status, usage = os.wait4(process.pid, 0)
                break
            time.sleep(0.02)
        wall = time.monotonic() - start
        process.returncode = os.waitstatus_to_exitcode(status)
    with open(out_path, errors="replace") as f:
        stdout = f.read()
    with open(err_path, errors="replace") as f:
        stderr = f.read()
    return process.returncode, stdout, stderr, usage.ru_utime + usage.ru_stime, wall, timed_out


def _base_row(task):
    row = {k: v for k, v in task.items() if k != "scene_text"}
    row.update({"task_id": task["id"], "worker": _worker_name(), "host": socket.gethostname(),
                "load_average_1min": os.getloadavg()[0]})
    return row


def _finish(row, status, stdout, stderr, cpu, wall, timed_out):
    row["exit_status"] = status
    row["process_cpu_s"] = cpu
    row["process_wall_s"] = wall
    if timed_out:
        row["outcome"] = "timeout"
        row["reason"] = "killed after the time limit of %g s" % row["time_limit"]
    if row.get("outcome") not in ("ok",) and stderr:
        row["stderr_tail"] = stderr[-STDERR_TAIL:]
    return row


def run_task(task, bin_dir, reference_text=None):
    """Runs one task (see study_file) and returns its row. Never raises for a failed process: a
    crash, a refusal or a timeout is a row with outcome "failed" or "timeout"."""
    row = _base_row(task)
    work_dir = tempfile.mkdtemp(prefix="birkhoff_cart_task_")
    try:
        scene = os.path.join(work_dir, task["scene"])
        with open(scene, "w") as f:
            f.write(task["scene_text"])
        if task["type"] == "simulate":
            return _simulate(task, row, bin_dir, scene, work_dir)
        command = [os.path.join(bin_dir, "work_precision"), "--scene", scene, "--duration", repr(task["duration"]),
                   "--checkpoints", ",".join(repr(t) for t in task["checkpoints"]), "--label", task["label"]]
        if task["type"] in ("reference", "reference_check"):
            output = os.path.join(work_dir, "reference.csv")
            command += ["--reference-run", "--reference-kind", task["reference_kind"], "--output", output]
            if task["type"] == "reference_check":
                command += ["--check-setting"]
        else:
            command += ["--measure", "--method", task["method"], "--repetitions", str(task["repetitions"])]
            if "step" in task:
                command += ["--step", repr(task["step"])]
            else:
                command += ["--tolerance", repr(task["tolerance"])]
            if "simulator_step" in task:
                command += ["--simulator-step", repr(task["simulator_step"])]
            if task.get("analytic"):
                command += ["--analytic-reference"]
            else:
                if reference_text is None:
                    row.update(outcome="failed", reason="its reference did not finish")
                    return row
                reference = os.path.join(work_dir, "reference.csv")
                with open(reference, "w") as f:
                    f.write(reference_text)
                command += ["--reference-file", reference]
        status, stdout, stderr, cpu, wall, timed_out = run_process(command, task["time_limit"], work_dir)
        result = None
        if not timed_out:
            try:
                result = json.loads(stdout.strip().splitlines()[-1]) if stdout.strip() else None
            except ValueError:
                result = None
        if result is not None:
            row["result"] = result
        if task["type"] in ("reference", "reference_check") and status == 0 and result is not None:
            with open(output) as f:
                row["reference_text"] = f.read()
        if timed_out:
            pass
        elif status == 0 and result is not None:
            row["outcome"] = "ok"
        elif status == 4 and result is not None:
            # The process worked and measured that the method cannot step this run (a step
            # failed: too large a step, a singularity): a result of the study, not a failure.
            row["outcome"] = "step_failed"
            row["reason"] = result.get("status")
        else:
            row["outcome"] = "failed"
            row["reason"] = (result or {}).get("status") or "exit status %d" % status
        return _finish(row, status, stdout, stderr, cpu, wall, timed_out)
    finally:
        shutil.rmtree(work_dir, ignore_errors=True)


def _simulate(task, row, bin_dir, scene, work_dir):
    """cart_simulate on the task's scene and settings: the row holds the exit status, the last CSV
    row (t, x, y, θ, energy) and, for a refusal, its one-line reason."""
    csv = os.path.join(work_dir, "out.csv")
    command = [os.path.join(bin_dir, "cart_simulate"), "--scene", scene, "--integrator", task["method"],
               "--output", csv, "--quiet"]
    # A study's `tolerances` are dopri5's local tolerance [-], or with step_control: reversible the
    # position error [m] the control aims at (cart_simulate's --position-tolerance).
    tolerance_option = "--position-tolerance" if task.get("step_control") == "reversible" else "--tolerance"
    for key, option in (("step", "--step"), ("tolerance", tolerance_option), ("duration", "--duration"),
                        ("output_rate", "--output-rate"), ("birkhoffian_form", "--birkhoffian-form"),
                        ("random_scene", "--random-scene")):
        if key in task:
            command += [option, str(task[key])]
    if task.get("step_control", "fixed") != "fixed":
        command += ["--step-control", task["step_control"]]
    status, stdout, stderr, cpu, wall, timed_out = run_process(command, task["time_limit"], work_dir)
    last = None
    if os.path.exists(csv):
        with open(csv) as f:
            lines = [line for line in f.read().splitlines() if line.strip()]
        if len(lines) > 1:
            header, values = lines[0].split(","), lines[-1].split(",")
            try:
                last = {name: float(value) if value else None for name, value in zip(header, values)}
            except ValueError:
                last = None
            row["rows"] = len(lines) - 1
    if last:
        row["result"] = {k: last.get(k) for k in ("t", "x", "y", "theta", "chi", "energy", "p2")}
        rhs = re.search(r"(\d+) rhs evaluations", stdout)
        if rhs:
            row["result"]["rhs_evaluations"] = int(rhs.group(1))
    if not timed_out:
        outcome, reason = judge(status, stderr, csv, task.get("start_time"), task.get("duration"), task.get("step", 0.0))
        if outcome == "refused" and task.get("expect") != "finish_or_refuse":
            outcome = "failed"
        row["outcome"] = outcome
        if reason:
            row["reason"] = reason
    return _finish(row, status, stdout, stderr, cpu, wall, timed_out)

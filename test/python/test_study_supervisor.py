"""No orphans, no leaks: a task's process runs under its worker thread's supervisor, which stops it
and removes the task directory when the task ends, passes its time limit, is cancelled, or when
the worker that started it dies (SIGKILL) — within a second, found by a marker in the process
table; the supervisor serves the thread's tasks one after the other."""
import os
import signal
import subprocess
import sys
import threading
import time
import uuid

import pytest

from birkhoff_cart_study.task_runner import Cancelled, Supervised, SupervisorFailed, SupervisorProcess, run_task
from conftest import REPOSITORY

SETTLE = 2.0  # [s] after which nothing of a stopped task may be left


def marked_sleeper(seconds=60.0):
    """A command that sleeps, with a marker of its own in its command line."""
    marker = "birkhoff_cart_test_%s" % uuid.uuid4().hex
    return [sys.executable, "-c", "import sys, time; time.sleep(float(sys.argv[1]))", str(seconds), marker], marker


def processes_with(marker):
    found = []
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                with open("/proc/%s/cmdline" % pid, "rb") as f:
                    if marker.encode() in f.read():
                        found.append(int(pid))
            except OSError:
                pass
    return found


def task_directories(tmp):
    return [name for name in os.listdir(tmp) if name.startswith("birkhoff_cart_task_")]


def wait_until(condition, limit):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


@pytest.fixture
def tmp(tmp_path, monkeypatch):
    directory = tmp_path / "tmp"
    directory.mkdir()
    monkeypatch.setenv("TMPDIR", str(directory))
    return str(directory)


def test_a_finished_process_leaves_its_outputs_until_the_row_is_made(tmp):
    with Supervised(["/bin/sh", "-c", "echo out; echo err >&2; cat input.txt > copy.txt; exit 3"],
                    {"input.txt": "hello"}, 10.0) as process:
        assert process.status == 3 and not process.timed_out
        assert process.stdout == "out\n" and process.stderr == "err\n"
        with open(process.path("copy.txt")) as f:
            assert f.read() == "hello"
        assert task_directories(tmp) == [os.path.basename(process.directory)]
    assert wait_until(lambda: not task_directories(tmp), SETTLE)


def test_past_its_time_limit_the_process_is_killed(tmp):
    command, marker = marked_sleeper()
    start = time.monotonic()
    with Supervised(command, {}, 0.5) as process:
        assert process.timed_out
    assert time.monotonic() - start < 5.0
    assert wait_until(lambda: not processes_with(marker) and not task_directories(tmp), SETTLE)


def test_a_cancelled_task_stops_its_process_within_a_second(tmp):
    command, marker = marked_sleeper()
    cancel_at = time.monotonic() + 0.5
    with pytest.raises(Cancelled):
        with Supervised(command, {}, 60.0, cancelled=lambda: time.monotonic() > cancel_at):
            pass
    assert time.monotonic() - cancel_at < 1.0
    assert wait_until(lambda: not processes_with(marker) and not task_directories(tmp), 1.0)


def test_a_task_whose_worker_is_killed_leaves_nothing(tmp):
    """The worker (here a Python process running run_task) dies by SIGKILL mid-task: its thread is
    gone, but the supervisor sees its lifeline close and stops the process."""
    command, marker = marked_sleeper()
    worker = subprocess.Popen([sys.executable, "-c", """
import sys
sys.path.insert(0, sys.argv[1])
from birkhoff_cart_study.task_runner import run_task
run_task({"id": "t", "argv": sys.argv[2:], "files": {"scene.yaml": "x"}, "time_limit": 60.0}, lambda w, p: {})
""", os.path.join(REPOSITORY, "src")] + command, start_new_session=True)
    assert wait_until(lambda: processes_with(marker) and task_directories(tmp), 20.0)
    os.killpg(worker.pid, signal.SIGKILL)  # the worker and anything in its group: not the supervisor's session
    worker.wait()
    killed = time.monotonic()
    assert wait_until(lambda: not processes_with(marker), 1.0), "the task's process outlived its worker"
    assert wait_until(lambda: not task_directories(tmp), SETTLE - (time.monotonic() - killed))


def test_run_task_makes_a_row_of_a_crash_and_of_a_missing_reference(tmp):
    row = run_task({"id": "t1", "label": "x", "argv": ["/bin/sh", "-c", "echo boom >&2; kill -SEGV $$"], "files": {},
                    "time_limit": 10.0}, lambda wire, process: {"outcome": "ok" if process.status == 0 else "failed"})
    assert row["outcome"] == "failed" and row["exit_status"] == -signal.SIGSEGV and "boom" in row["stderr_tail"]
    assert row["task_id"] == "t1" and row["process_cpu_s"] >= 0.0
    row = run_task({"id": "t2", "argv": ["/bin/true"], "files": {}, "time_limit": 10.0, "needs_reference": True},
                   lambda wire, process: {"outcome": "ok"}, reference={"outcome": "failed"})
    assert row == dict(row, outcome="failed", reason="its reference did not finish")
    assert not task_directories(tmp)


def test_a_worker_thread_reuses_its_supervisor_and_a_cancelled_task_leaves_it_usable(tmp):
    pool = {}
    pids = []
    for _ in range(3):
        with Supervised(["/bin/sh", "-c", "exit 0"], {}, 10.0, pool=pool) as process:
            assert process.status == 0
        pids.append(pool[threading.get_ident()]["process"].pid)
    assert len(set(pids)) == 1  # one supervisor process for the thread's tasks
    command, marker = marked_sleeper()
    cancel_at = time.monotonic() + 0.3
    with pytest.raises(Cancelled):
        with Supervised(command, {}, 60.0, cancelled=lambda: time.monotonic() > cancel_at, pool=pool):
            pass
    assert wait_until(lambda: not processes_with(marker) and not task_directories(tmp), 1.0)
    with Supervised(["/bin/sh", "-c", "exit 7"], {}, 10.0, pool=pool) as process:
        assert process.status == 7
    assert pool[threading.get_ident()]["process"].pid == pids[0]
    with pytest.raises(SupervisorFailed, match="cannot start /nonexistent/engine"):
        with Supervised(["/nonexistent/engine"], {}, 10.0, pool=pool):
            pass
    assert not task_directories(tmp)
    for state in pool.values():
        SupervisorProcess(state).close()

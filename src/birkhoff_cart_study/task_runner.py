"""One task = one process of the batch engine, run on a Dask worker; returns one row (a dict).

This module is what workers execute: it needs only the standard library and the package's
executables (the task's argument list names them by their path, the same on every worker). The
process runs under its supervisor (supervisor.py), a process of its own that outlives the worker's
thread: it enforces the time limit, and it kills the process and removes the task directory as
soon as the worker lets go of it — the task done, cancelled (the runner's SIGINT or SIGTERM, its
client gone), or the worker dead."""
import json
import os
import select
import signal
import socket
import subprocess
import sys
import time

STDERR_TAIL = 2000         # characters of a failed process's stderr kept in its row
OUTPUT_CAP = 4 * 2 ** 20   # [bytes] of the process's stdout and stderr read back
POLL = 0.05                # [s] between looks at the task's cancellation
SUPERVISOR_GRACE = 30.0    # [s] past the time limit before the supervisor itself is given up on

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "supervisor.py")) as _source:
    SUPERVISOR_SOURCE = _source.read()


class Cancelled(Exception):
    """The task was cancelled while its process ran; the process is stopped, its directory gone."""


class SupervisorFailed(Exception):
    """The supervisor could not run the process (or ended without a word)."""


def _worker_name():
    try:
        from distributed import get_worker
        return get_worker().name
    except (ImportError, ValueError):
        return "local"


def dask_task_cancelled():
    """True when the Dask task this thread runs has been cancelled or released (the runner
    cancelled it, or its client is gone); False outside a Dask worker."""
    try:
        from distributed import get_worker
        from distributed.worker import thread_state
        worker = get_worker()
    except (ImportError, ValueError):
        return False
    key = getattr(thread_state, "key", None)
    if key is None:
        return False
    state = worker.state.tasks.get(key)
    return state is None or state.state in ("cancelled", "released", "forgotten")


def _tail(path, cap=OUTPUT_CAP):
    try:
        with open(path, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            if size > cap:
                f.seek(size - cap)
            return f.read().decode(errors="replace")
    except OSError:
        return ""


class Process:
    """What the task's process did: exit status, CPU and wall seconds, timed_out, its stdout and
    stderr, and the task directory where its output files still are (until the row is made)."""

    def __init__(self, report, directory):
        self.status = report["status"]
        self.cpu_s = report["cpu_s"]
        self.wall_s = report["wall_s"]
        self.timed_out = report["timed_out"]
        self.directory = directory
        self.stdout = _tail(os.path.join(directory, "stdout"))
        self.stderr = _tail(os.path.join(directory, "stderr"))

    def path(self, name):
        return os.path.join(self.directory, name)


class Supervised:
    """`with Supervised(argv, files, time_limit) as process:` runs argv under its supervisor and
    gives the Process; leaving the block lets the supervisor kill what is left and remove the task
    directory. Raises Cancelled when `cancelled()` turns true first."""

    def __init__(self, argv, files, time_limit, cancelled=dask_task_cancelled):
        self.spec = {"argv": argv, "files": files, "time_limit": time_limit}
        self.cancelled = cancelled
        self.deadline = time.monotonic() + time_limit + SUPERVISOR_GRACE
        self.buffer = b""
        self.supervisor = None

    def _line(self):
        fd = self.supervisor.stdout.fileno()
        while b"\n" not in self.buffer:
            ready, _, _ = select.select([fd], [], [], POLL)
            if ready:
                chunk = os.read(fd, 65536)
                if not chunk:
                    raise SupervisorFailed("the supervisor ended without a result: %s"
                                           % self.supervisor.stderr.read(2000).decode(errors="replace").strip()[-300:])
                self.buffer += chunk
            elif self.cancelled():
                raise Cancelled()
            elif time.monotonic() > self.deadline:
                raise SupervisorFailed("no result from the supervisor %g s past the time limit" % SUPERVISOR_GRACE)
        line, self.buffer = self.buffer.split(b"\n", 1)
        return json.loads(line)

    def __enter__(self):
        self.supervisor = subprocess.Popen([sys.executable, "-I", "-S", "-c", SUPERVISOR_SOURCE, json.dumps(self.spec)],
                                           stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                           start_new_session=True)
        try:
            started = self._line()
            return Process(self._line(), started["directory"])
        except BaseException:
            self.__exit__(None, None, None)
            raise

    def __exit__(self, *exception):
        self.supervisor.stdin.close()  # the lifeline: the supervisor kills, cleans up and exits
        try:
            self.supervisor.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.supervisor.send_signal(signal.SIGTERM)
            try:
                self.supervisor.wait(timeout=2)
            except subprocess.TimeoutExpired:
                self.supervisor.kill()
                self.supervisor.wait()
        self.supervisor.stdout.close()
        self.supervisor.stderr.close()
        return False


def base_row(wire):
    """The task's fields and where it runs."""
    skip = ("argv", "files", "needs_reference", "study_kind", "id", "scene_text")
    row = {k: v for k, v in wire.items() if k not in skip}
    row.update({"task_id": wire["id"], "worker": _worker_name(), "host": socket.gethostname(),
                "load_average_1min": os.getloadavg()[0]})
    return row


def run_task(wire, outcome, reference=None, cancelled=dask_task_cancelled):
    """Runs one task (its `wire`: tasks.Task.wire plus argv, files, needs_reference) and returns its
    row. `outcome(wire, process)` is the study kind's judgement of the process (a dict for the row);
    `reference` the row of the reference a measurement needs. Never raises for a failed process: a
    crash, a refusal or a timeout is a row with outcome "failed" or "timeout"; raises Cancelled
    when the task is cancelled while it runs."""
    row = base_row(wire)
    files = dict(wire["files"])
    if wire.get("needs_reference"):
        text = (reference or {}).get("reference_text") if (reference or {}).get("outcome") == "ok" else None
        if text is None:
            row.update(outcome="failed", reason="its reference did not finish")
            return row
        files["reference.csv"] = text
    try:
        with Supervised(wire["argv"], files, wire["time_limit"], cancelled) as process:
            row.update(outcome(wire, process))
    except SupervisorFailed as error:
        row.update(outcome="failed", reason=str(error))
        return row
    row["exit_status"] = process.status
    row["process_cpu_s"] = process.cpu_s
    row["process_wall_s"] = process.wall_s
    if process.timed_out:
        row["outcome"] = "timeout"
        row["reason"] = "killed after the time limit of %g s" % wire["time_limit"]
    if row.get("outcome") != "ok" and process.stderr:
        row["stderr_tail"] = process.stderr[-STDERR_TAIL:]
    return row

"""One task = one process of the batch engine, run on a Dask worker; returns one row (a dict).

This module is what workers execute: it needs only the standard library and the package's
executables (the task's argument list names them by their path, the same on every worker). The
process runs under its worker thread's supervisor (supervisor.py), a process of its own, started
once and reused task after task, that outlives the worker and its thread: it enforces the time
limit, removes the task directory when the row is made, and stops the process and removes its
directory as soon as the task is cancelled (the runner's SIGINT or SIGTERM, its client gone) or
the worker is gone, however it ended."""
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
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


class SupervisorProcess:
    """A running supervisor (supervisor.py) and its command channel: JSON lines both ways.

    Its state is a plain dict (the process, the unread answers, the latest task's id), which a
    worker keeps across tasks: each task's code arrives by value, with classes of its own, so a
    worker must not hold objects of an earlier task's classes (their exceptions would not be the
    ones the later code catches)."""

    def __init__(self, state=None):
        if state is None:
            state = {"process": subprocess.Popen([sys.executable, "-I", "-S", "-c", SUPERVISOR_SOURCE],
                                                 stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                                 start_new_session=True),
                     "buffer": b"", "task": 0}
        self.state = state
        self.process = state["process"]

    @property
    def task(self):
        return self.state["task"]

    def alive(self):
        return self.process.poll() is None

    def send(self, message):
        try:
            self.process.stdin.write((json.dumps(message) + "\n").encode())
            self.process.stdin.flush()
        except (BrokenPipeError, ValueError):
            raise SupervisorFailed("the supervisor is gone")

    def run(self, spec):
        """Sends a task; returns its id (every answer about it carries it)."""
        self.state["task"] += 1
        self.send(dict(spec, id=self.task))
        return self.task

    def answer(self, cancelled, deadline):
        """The supervisor's next answer about the latest task (a late answer about a cancelled one
        is skipped); Cancelled when `cancelled()` turns true first."""
        while True:
            message = self._line(cancelled, deadline)
            if message.get("id") == self.task:
                return message

    def _line(self, cancelled, deadline):
        fd = self.process.stdout.fileno()
        while b"\n" not in self.state["buffer"]:
            ready, _, _ = select.select([fd], [], [], POLL)
            if ready:
                chunk = os.read(fd, 65536)
                if not chunk:
                    self.process.wait()
                    raise SupervisorFailed("the supervisor ended without a result (exit %s): %s" % (
                        self.process.returncode, self.process.stderr.read(2000).decode(errors="replace").strip()[-300:]))
                self.state["buffer"] += chunk
            elif cancelled():
                raise Cancelled()
            elif time.monotonic() > deadline:
                raise SupervisorFailed("no result from the supervisor %g s past the time limit" % SUPERVISOR_GRACE)
        line, self.state["buffer"] = self.state["buffer"].split(b"\n", 1)
        return json.loads(line)

    def close(self):
        """Closes the lifeline: the supervisor kills what runs, cleans up and exits."""
        try:
            self.process.stdin.close()
        except (BrokenPipeError, ValueError):
            pass
        try:
            self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=2)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.process.stdout.close()
        self.process.stderr.close()


def worker_supervisors():
    """The supervisors of this Dask worker's threads ({thread id: a SupervisorProcess's state}),
    kept on the Worker object, which outlives its tasks; None outside a worker."""
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        return None
    pool = getattr(worker, "_birkhoff_cart_supervisors", None)
    if pool is None:
        pool = worker._birkhoff_cart_supervisors = {}
    return pool


class Supervised:
    """`with Supervised(argv, files, time_limit) as process:` runs argv under the thread's
    supervisor and gives the Process; leaving the block lets the supervisor remove the task
    directory. Raises Cancelled when `cancelled()` turns true first (the supervisor then stops the
    process). `pool`: the worker's supervisors, one per thread, reused task after task; without
    one, a supervisor of its own is started and closed around the task."""

    def __init__(self, argv, files, time_limit, cancelled=dask_task_cancelled, pool=None):
        self.spec = {"op": "run", "argv": argv, "files": files, "time_limit": time_limit}
        self.cancelled = cancelled
        self.deadline = time.monotonic() + time_limit + SUPERVISOR_GRACE
        self.pool = pool
        self.supervisor = None

    def _supervisor(self):
        if self.pool is None:
            return SupervisorProcess()
        thread = threading.get_ident()
        living = {t.ident for t in threading.enumerate()}
        for ident in [i for i in self.pool if i not in living]:  # a thread gone: its supervisor too
            SupervisorProcess(self.pool.pop(ident)).close()
        state = self.pool.get(thread)
        supervisor = SupervisorProcess(state) if state is not None else None
        if supervisor is None or not supervisor.alive():
            supervisor = SupervisorProcess()
            self.pool[thread] = supervisor.state
        return supervisor

    def __enter__(self):
        self.supervisor = self._supervisor()
        try:
            self.supervisor.run(self.spec)
            started = self.supervisor.answer(self.cancelled, self.deadline)
            if "error" in started:
                raise SupervisorFailed(started["error"])
            return Process(self.supervisor.answer(self.cancelled, self.deadline), started["directory"])
        except Cancelled:
            self._finish("stop")
            raise
        except SupervisorFailed:
            self._discard()
            raise

    def _finish(self, op):
        try:
            self.supervisor.send({"op": op, "id": self.supervisor.task})
        except SupervisorFailed:
            self._discard()
            return
        if self.pool is None:
            self.supervisor.close()

    def _discard(self):
        if self.pool is not None and self.pool.get(threading.get_ident()) is self.supervisor.state:
            del self.pool[threading.get_ident()]
        self.supervisor.close()

    def __exit__(self, *exception):
        self._finish("done")
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
        with Supervised(wire["argv"], files, wire["time_limit"], cancelled, worker_supervisors()) as process:
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

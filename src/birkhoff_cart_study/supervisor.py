"""The supervisor of a worker thread's task processes: a process of its own (`python3 -I -S -c
SOURCE`), started once per worker thread in a session of its own, so that it outlives the worker
and its thread; it runs that thread's tasks one after the other.

Its standard input is the lifeline and its command channel: the worker holds the other end. The
worker writes one JSON line per command and reads one JSON line per answer on its standard output:
    {"op": "run", "id": N, "argv": [...], "files": {NAME: TEXT}, "time_limit": SECONDS}
        → {"directory": DIR, "pid": PID}  once the task's process has started in a new task
          directory (birkhoff_cart_task_* in $TMPDIR, with the files written there) and a new
          process group that dies with the supervisor (PR_SET_PDEATHSIG), or {"error": WHY};
        → {"status": S, "cpu_s": C, "wall_s": W, "timed_out": B}  when it has ended, or was
          killed past its time limit (what is left of its group is killed too);
    {"op": "done", "id": N}   the worker has read the outputs: the directory is removed;
    {"op": "stop", "id": N}   the task is cancelled: its process group is killed, its directory removed.
Every answer carries the id of its task, and a command for another task than the running one is
ignored: a cancelled task's late answer never passes for the next task's.
Whenever the lifeline closes — the worker is done with its thread, or died, however — the
supervisor kills the running process group, removes the directory and exits: no orphan, no leaked
directory. Standard library only (it runs without the package on any worker)."""
import ctypes
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time

POLL = 0.02  # [s] between looks at the lifeline and the running process
PR_SET_PDEATHSIG = 1


class LifelineClosed(Exception):
    pass


def _die_with_parent():
    """In the child, before exec: SIGKILL when the supervisor (its parent) dies."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def _kill_group(pid):
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


class Commands:
    """The JSON lines on standard input; LifelineClosed at its end."""

    def __init__(self):
        self.buffer = b""

    def next(self, timeout=None):
        """The next command, or None when none came within `timeout` [s] (None: wait)."""
        while b"\n" not in self.buffer:
            ready, _, _ = select.select([0], [], [], timeout)
            if not ready:
                return None
            chunk = os.read(0, 65536)
            if not chunk:
                raise LifelineClosed()
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\n", 1)
        return json.loads(line)


def _say(message):
    sys.stdout.write(json.dumps(message) + "\n")
    sys.stdout.flush()


class Task:
    """One task's directory and process group."""

    def __init__(self, spec):
        self.id = spec.get("id")
        self.directory = tempfile.mkdtemp(prefix="birkhoff_cart_task_")
        self.child = None
        for name, text in spec.get("files", {}).items():
            with open(os.path.join(self.directory, os.path.basename(name)), "w") as f:
                f.write(text)
        try:
            with open(os.path.join(self.directory, "stdout"), "wb") as out, \
                    open(os.path.join(self.directory, "stderr"), "wb") as err:
                self.start = time.monotonic()
                self.child = subprocess.Popen(spec["argv"], cwd=self.directory, stdout=out, stderr=err,
                                              stdin=subprocess.DEVNULL, start_new_session=True,
                                              preexec_fn=_die_with_parent)
        except OSError:
            shutil.rmtree(self.directory, ignore_errors=True)
            raise

    def wait(self, commands, time_limit):
        """The report once the process ends (or is killed past `time_limit`); None when the task
        was stopped meanwhile."""
        timed_out = False
        while True:
            pid, status, usage = os.wait4(self.child.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - self.start > time_limit:
                timed_out = True
                _kill_group(self.child.pid)
                pid, status, usage = os.wait4(self.child.pid, 0)
                break
            command = commands.next(POLL)
            if command is not None and command.get("op") == "stop" and command.get("id") == self.id:
                return None
        wall = time.monotonic() - self.start
        _kill_group(self.child.pid)  # whatever the process left behind in its group
        self.child.returncode = os.waitstatus_to_exitcode(status)
        return {"status": self.child.returncode, "cpu_s": usage.ru_utime + usage.ru_stime, "wall_s": wall,
                "timed_out": timed_out}

    def remove(self):
        if self.child is not None and self.child.returncode is None:
            _kill_group(self.child.pid)
            try:
                os.waitpid(self.child.pid, 0)
            except ChildProcessError:
                pass
        shutil.rmtree(self.directory, ignore_errors=True)


def _stop(number, frame):
    raise LifelineClosed()  # SIGTERM, SIGHUP: kill and clean up as for a closed lifeline


def main():
    for number in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, _stop)
    commands = Commands()
    task = None
    try:
        while True:
            command = commands.next()
            if command.get("op") != "run":
                continue  # a late "done" or "stop" of a task already cleaned up
            try:
                task = Task(command)
            except OSError as error:
                _say({"id": command.get("id"), "error": "cannot start %s: %s" % (command["argv"][0],
                                                                                  error.strerror or error)})
                continue
            _say({"id": task.id, "directory": task.directory, "pid": task.child.pid})
            report = task.wait(commands, command["time_limit"])
            if report is not None:
                _say(dict(report, id=task.id))
                while not (command.get("op") in ("done", "stop") and command.get("id") == task.id):
                    command = commands.next()
            task.remove()
            task = None
    except (LifelineClosed, BrokenPipeError):
        return 0
    finally:
        if task is not None:
            task.remove()


if __name__ == "__main__":
    sys.exit(main())

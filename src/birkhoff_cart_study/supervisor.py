"""The supervisor of one task's process: run as its own process (`python3 -I -S -c SOURCE SPEC`) in
a session of its own by the worker's thread, so that it outlives the worker and its thread.

It makes the task directory (birkhoff_cart_task_* in $TMPDIR), writes the task's input files there
and starts the task's process in a new process group, which dies with the supervisor
(PR_SET_PDEATHSIG). Its standard input is the lifeline: the worker holds the other end and never
writes. The supervisor prints two JSON lines on standard output,
    {"directory": DIR, "pid": PID}                              once the process has started,
    {"status": S, "cpu_s": C, "wall_s": W, "timed_out": B}    when it has ended (or was killed
                                                                past the time limit),
and then waits for the lifeline to close (the worker has read the outputs). Whenever the lifeline
closes — the task is done or cancelled, or its worker died, however — the supervisor kills the
process group, removes the directory and exits: no orphan, no leaked directory.

SPEC is a JSON object: {"argv": [...], "files": {NAME: TEXT}, "time_limit": SECONDS}. Standard
library only (it runs without the package on any worker)."""
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

POLL = 0.02  # [s] between looks at the lifeline and the process
PR_SET_PDEATHSIG = 1


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


def _lifeline_closed(timeout):
    """True when the worker's end of standard input is closed (EOF) within `timeout` [s]."""
    ready, _, _ = select.select([0], [], [], timeout)
    return bool(ready) and os.read(0, 4096) == b""


def _say(message):
    sys.stdout.write(json.dumps(message) + "\n")
    sys.stdout.flush()


def _stop(number, frame):
    raise SystemExit(3)  # SIGTERM, SIGHUP: kill and clean up as for a closed lifeline


def main():
    for number in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, _stop)
    spec = json.loads(sys.argv[1])
    directory = tempfile.mkdtemp(prefix="birkhoff_cart_task_")
    child = None
    try:
        for name, text in spec.get("files", {}).items():
            with open(os.path.join(directory, os.path.basename(name)), "w") as f:
                f.write(text)
        with open(os.path.join(directory, "stdout"), "wb") as out, open(os.path.join(directory, "stderr"), "wb") as err:
            start = time.monotonic()
            child = subprocess.Popen(spec["argv"], cwd=directory, stdout=out, stderr=err, stdin=subprocess.DEVNULL,
                                     start_new_session=True, preexec_fn=_die_with_parent)
        _say({"directory": directory, "pid": child.pid})
        timed_out = False
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > spec["time_limit"]:
                timed_out = True
                _kill_group(child.pid)
                pid, status, usage = os.wait4(child.pid, 0)
                break
            if _lifeline_closed(POLL):
                return 3  # cancelled, or the worker is gone: the finally clause kills and cleans
        wall = time.monotonic() - start
        _kill_group(child.pid)  # whatever the process left behind in its group
        child.returncode = os.waitstatus_to_exitcode(status)
        _say({"status": child.returncode, "cpu_s": usage.ru_utime + usage.ru_stime, "wall_s": wall,
              "timed_out": timed_out})
        while not _lifeline_closed(1.0):
            pass
        return 0
    finally:
        if child is not None and child.returncode is None:
            _kill_group(child.pid)
            try:
                os.waitpid(child.pid, 0)
            except ChildProcessError:
                pass
        shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:  # the worker is gone before reading: nothing to tell
        sys.exit(3)

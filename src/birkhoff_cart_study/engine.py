"""Running a study on Dask distributed: rows appended as tasks finish, resume, progress, summary.

The default is an embedded LocalCluster with one single-threaded worker process per core; with a
scheduler address the same tasks go to any Dask cluster whose workers have the package installed
at the same path. A worker that dies mid-task has its task rerun elsewhere by the scheduler; a
task whose process crashes or passes its time limit comes back as a failed row, so the study
never hangs on one task."""
import json
import logging
import fcntl
import os
import signal
import sys
import time

from .task_runner import run_task

ROWS_FILE = "rows.jsonl"
TASK_RETRIES = 2  # reruns of a task whose worker died (besides the scheduler's own reassignment)


def read_rows(path):
    """The complete rows of a rows file (a torn last line from an interrupted write is ignored)."""
    rows = []
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        for line in f:
            if not line.endswith("\n"):
                break
            try:
                rows.append(json.loads(line))
            except ValueError:
                continue
    return rows


class RowWriter:
    """Appends one JSON row per line; each row is written whole, flushed and synced, so a row is
    complete or absent whatever interrupts the study."""

    def __init__(self, path):
        self.path = path
        # Cut a torn last line left by an interrupted write, so appended rows start on a line.
        if os.path.exists(path):
            with open(path, "rb+") as f:
                data = f.read()
                if data and not data.endswith(b"\n"):
                    f.truncate(data.rfind(b"\n") + 1)
        self.file = open(path, "a")

    def write(self, row):
        self.file.write(json.dumps(row, sort_keys=True) + "\n")
        self.file.flush()
        os.fsync(self.file.fileno())

    def close(self):
        self.file.close()


def _duration(seconds):
    if seconds < 60:
        return "%.1fs" % seconds
    seconds = int(round(seconds))
    if seconds >= 3600:
        return "%dh%02dm%02ds" % (seconds // 3600, seconds % 3600 // 60, seconds % 60)
    return "%dm%02ds" % (seconds // 60, seconds % 60)


class Progress:
    """tasks done / total with an ETA from the rate so far, at most once a second (and at the end)."""

    def __init__(self, total, already, stream=sys.stderr):
        self.total, self.done, self.failed = total, already, 0
        self.started, self.already, self.last = time.monotonic(), already, 0.0
        self.stream = stream

    def update(self, row):
        self.done += 1
        if row.get("outcome") in ("failed", "timeout"):
            self.failed += 1
        now = time.monotonic()
        if now - self.last >= 1.0 or self.done == self.total:
            self.last = now
            elapsed = now - self.started
            finished_here = self.done - self.already
            remaining = self.total - self.done
            eta = elapsed / finished_here * remaining if finished_here else float("nan")
            self.stream.write("study: %d/%d tasks done (%d failed), elapsed %s, ETA %s\n"
                              % (self.done, self.total, self.failed, _duration(elapsed),
                                 _duration(eta) if eta == eta else "?"))
            self.stream.flush()


def make_client(scheduler, workers):
    """A Dask client: on `scheduler` (tcp://HOST:PORT) or on an embedded LocalCluster of `workers`
    single-threaded worker processes (default: one per core)."""
    import cloudpickle
    from distributed import Client, LocalCluster
    import birkhoff_cart_study
    from birkhoff_cart_study import cli_contract, task_runner
    # The tasks' code travels with them: workers started by `dask-worker` need the package's
    # executables, not its Python modules on their path. (Dask pickles by value only functions
    # whose own module is registered, hence each module by name.)
    for module in (birkhoff_cart_study, cli_contract, task_runner, sys.modules[__name__]):
        cloudpickle.register_pickle_by_value(module)
    if scheduler:
        client = Client(scheduler, timeout="30s")
        client.wait_for_workers(1, timeout=300)
        return client, None
    cluster = LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster), cluster


def latest_rows(rows):
    """One row per task: the last one written (a task rerun with --retry-failed appends a new row)."""
    latest = {}
    for row in rows:
        latest[row["task_id"]] = row
    return list(latest.values())


def run_study(study, tasks, output_dir, bin_dir, scheduler=None, workers=None, stream=sys.stderr,
              retry_failed=False):
    """Runs the tasks not yet in output_dir/rows.jsonl (and, with retry_failed, those whose row
    failed or timed out); returns (the latest row of every task, summary line)."""
    from distributed import as_completed
    os.makedirs(output_dir, exist_ok=True)
    rows_path = os.path.join(output_dir, ROWS_FILE)
    lock = open(os.path.join(output_dir, ".lock"), "w")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)  # held until this process ends
    except OSError:
        raise RuntimeError("another study runner is writing %s; wait for it or stop it first" % output_dir)
    previous = latest_rows(read_rows(rows_path))
    if retry_failed:
        previous = [row for row in previous if row.get("outcome") not in ("failed", "timeout")]
    done_ids = {row["task_id"] for row in previous}
    todo = [task for task in tasks if task["id"] not in done_ids]
    references = {row["label"]: row.get("reference_text") for row in previous
                  if row.get("type") == "reference" and row.get("outcome") == "ok"}
    wall_start = time.monotonic()
    client, cluster = make_client(scheduler, workers)
    writer = RowWriter(rows_path)
    new_rows = []
    try:
        worker_count = len(client.scheduler_info()["workers"])
        stream.write("study %s: %d tasks, %d already done, %d to run on %d Dask worker(s)%s\n"
                     % (study["name"], len(tasks), len(tasks) - len(todo), len(todo), worker_count,
                        " at " + scheduler if scheduler else " (local cluster)"))
        progress = Progress(len(tasks), len(tasks) - len(todo), stream)
        reference_futures = {}
        futures = {}
        for task in todo:
            if task["type"] == "reference":
                future = client.submit(run_task, task, bin_dir, key="reference-" + task["id"], pure=False,
                                       retries=TASK_RETRIES)
                reference_futures[task["label"]] = future
                futures[future] = task
        for label, future in reference_futures.items():
            references[label] = client.submit(_reference_text, future, key="reference-text-" + label, pure=False)
        for task in todo:
            if task["type"] == "reference":
                continue
            reference = references.get(task.get("reference")) if task["type"] == "measure" and not task.get("analytic") else None
            future = client.submit(run_task, task, bin_dir, reference, key="task-" + task["id"], pure=False,
                                   retries=TASK_RETRIES, priority=expected_cost(task))
            futures[future] = task
        # SIGINT and SIGTERM stop the study between rows: polled, because a wait inside Dask's
        # client does not always let Python's KeyboardInterrupt through.
        stop = []
        previous_handlers = {sig: signal.signal(sig, lambda number, frame: stop.append(number))
                             for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            pending = as_completed(list(futures))
            while not pending.is_empty() and not stop:
                for future in pending.next_batch(block=False):
                    task = futures[future]
                    try:
                        row = future.result()
                    except Exception as error:  # the task could not run at all (e.g. its workers kept dying)
                        row = {k: v for k, v in task.items() if k != "scene_text"}
                        row.update(task_id=task["id"], outcome="failed",
                                   reason="%s: %s" % (type(error).__name__, error))
                    row["workers"] = worker_count
                    writer.write(row)
                    new_rows.append(row)
                    progress.update(row)
                time.sleep(0.05)
        finally:
            for sig, handler in previous_handlers.items():
                signal.signal(sig, handler)
        if stop:
            client.cancel(list(futures))
            raise KeyboardInterrupt
    finally:
        writer.close()
        client.close()
        if cluster is not None:
            cluster.close()
    rows = previous + new_rows
    wall = time.monotonic() - wall_start
    counts = {}
    for row in rows:
        if row["task_id"] in {t["id"] for t in tasks}:
            counts[row.get("outcome", "failed")] = counts.get(row.get("outcome", "failed"), 0) + 1
    cpu = sum(row.get("process_cpu_s", 0.0) or 0.0 for row in new_rows)
    summary = ("study %s: %d tasks: %s; %d run now (%d resumed from earlier rows) in %s wall, %s CPU on %d worker(s); rows %s"
               % (study["name"], len(tasks), ", ".join("%d %s" % (n, k) for k, n in sorted(counts.items())),
                  len(new_rows), len(tasks) - len(todo), _duration(wall), _duration(cpu), worker_count, rows_path))
    return rows, summary


def expected_cost(task):
    """A rough rank of a task's cost (larger runs first, so that the longest ones do not start last
    and leave the other workers idle at the end): the simulated time, and for a fixed step the
    number of steps."""
    duration = task.get("duration") or 1.0
    steps = duration / task["step"] if task.get("step") else duration * 10.0
    return int(min(steps, 1e12))


def _reference_text(row):
    """The reference file a measurement reads, from its reference task's row (None when it failed)."""
    return row.get("reference_text") if row.get("outcome") == "ok" else None

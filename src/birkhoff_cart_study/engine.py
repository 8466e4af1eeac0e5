"""Running a study on Dask distributed: rows appended as tasks finish, resume, progress, summary.

The default is an embedded LocalCluster on 127.0.0.1 (scheduler, workers and their HTTP servers:
nothing listens beyond this machine) with one single-threaded worker process per core; each worker
process exits as soon as the runner is gone, however it ended (its nanny's pipe closes). With a scheduler address
(tcp:// or tls:// with certificates) the same tasks go to any Dask cluster whose workers have the
package's executables at the same path. A worker that dies mid-task has its task rerun elsewhere
by the scheduler; a task whose process crashes or passes its time limit comes back as a failed row,
so the study never hangs on one task. Tasks are submitted in a window of a few per worker, so a
study of hundreds of thousands of tasks holds only the window in the scheduler's memory."""
import json
import logging
import os
import signal
import sys
import time

from .kinds import module_of

ROWS_FILE = "rows.jsonl"
TASK_RETRIES = 2       # reruns of a task whose worker died (besides the scheduler's own reassignment)
WINDOW_PER_WORKER = 4  # tasks in flight per worker thread
MIN_WINDOW = 16
WORKER_WAIT = 300.0    # [s] a scheduler may take to have its first worker
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


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
                row = json.loads(line)
            except ValueError:
                continue
            if isinstance(row, dict) and isinstance(row.get("task_id"), str):
                rows.append(row)
    return rows


class RowWriter:
    """Appends one JSON row per line; each row is written whole, flushed and synced, so a row is
    complete or absent whatever interrupts the study."""

    def __init__(self, path, build=None):
        self.path = path
        self.build = build  # the source commit that measures the rows (report.source_commit), stamped on each
        # Cut a torn last line left by an interrupted write, so appended rows start on a line.
        if os.path.exists(path):
            with open(path, "rb+") as f:
                data = f.read()
                if data and not data.endswith(b"\n"):
                    f.truncate(data.rfind(b"\n") + 1)
        self.file = open(path, "a")

    def write(self, row):
        if self.build is not None:
            row.setdefault("build", self.build)  # in place: the report reads the same row
        self.file.write(json.dumps(row, sort_keys=True) + "\n")
        self.file.flush()
        os.fsync(self.file.fileno())

    def close(self):
        self.file.close()


def duration_text(seconds):
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
                              % (self.done, self.total, self.failed, duration_text(elapsed),
                                 duration_text(eta) if eta == eta else "?"))
            self.stream.flush()


class SchedulerUnreachable(Exception):
    """The scheduler at the given address did not answer (or had no worker) in time."""


def _register_code():
    """The tasks' code travels with them: workers started by `dask-worker` need the package's
    executables, not its Python modules on their path. (Dask pickles by value only a submitted
    function whose own module is registered, hence each module by name, and each kind's `run` is
    the function submitted: a function passed as an argument would go by reference.)"""
    import cloudpickle
    import birkhoff_cart_study
    from birkhoff_cart_study import cli_contract, kinds, race, task_runner, tasks
    for module in (birkhoff_cart_study, cli_contract, race, task_runner, tasks, *kinds.MODULES,
                   sys.modules[__name__]):
        cloudpickle.register_pickle_by_value(module)


def make_client(scheduler, workers, security=None, timeout=10.0):
    """A Dask client: on `scheduler` (tcp:// or tls://HOST:PORT, reached within `timeout` [s]) or on
    an embedded LocalCluster of `workers` single-threaded worker processes on 127.0.0.1 (default:
    one per core). Returns (client, cluster or None)."""
    from distributed import Client, LocalCluster
    _register_code()
    if scheduler:
        try:
            client = Client(scheduler, timeout="%gs" % timeout, security=security)
        except (OSError, TimeoutError) as error:
            raise SchedulerUnreachable("cannot reach the scheduler at %s within %g s: %s"
                                       % (scheduler, timeout, str(error)[:300]))
        try:
            client.wait_for_workers(1, timeout=WORKER_WAIT)
        except (OSError, TimeoutError):
            client.close()
            raise SchedulerUnreachable("the scheduler at %s has no worker after %g s" % (scheduler, WORKER_WAIT))
        return client, None
    cluster = LocalCluster(n_workers=workers or os.cpu_count(), threads_per_worker=1, processes=True,
                           host="127.0.0.1", dashboard_address=None, worker_dashboard_address="127.0.0.1:0",
                           scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=logging.ERROR)
    return Client(cluster), cluster


def latest_rows(rows):
    """One row per task: the last one written (a task rerun with --retry-failed appends a new row)."""
    latest = {}
    for row in rows:
        latest[row["task_id"]] = row
    return list(latest.values())


def expected_cost(task):
    """A rough rank of a task's cost (larger runs first, so that the longest ones do not start last
    and leave the other workers idle at the end): the simulated time, and for a fixed step the
    number of steps."""
    duration = task.settings.get("duration") or 1.0
    steps = duration / task.settings["step"] if task.settings.get("step") else duration * 10.0
    return int(min(steps, 1e12))


def _failed_row(task, error):
    row = dict(task.fields(), task_id=task.id, outcome="failed",
               reason="%s: %s" % (type(error).__name__, str(error)[:300]))
    return row


def run_study(study, tasks, output_dir, bin_dir, scheduler=None, workers=None, stream=sys.stderr,
              retry_failed=False, security=None, connect_timeout=10.0):
    """Runs the tasks not yet in output_dir/rows.jsonl (and, with retry_failed, those whose row
    failed or timed out); returns (the latest row of every task, summary line). The caller holds
    the output directory's lock. SIGINT or SIGTERM cancels the running tasks (their processes stop
    within a second) and raises KeyboardInterrupt with the signal's number as its argument."""
    from distributed import as_completed
    kind = module_of(study["kind"])
    rows_path = os.path.join(output_dir, ROWS_FILE)
    previous = latest_rows(read_rows(rows_path))
    if retry_failed:
        previous = [row for row in previous if row.get("outcome") not in ("failed", "timeout")]
    done_ids = {row["task_id"] for row in previous}
    todo = [task for task in tasks if task.id not in done_ids]
    references = {row.get("label"): row for row in previous if row.get("type") == "reference" and row.get("outcome") == "ok"}
    wall_start = time.monotonic()
    stop = []
    handlers = {number: signal.signal(number, lambda n, frame: stop.append(n)) for number in STOP_SIGNALS}
    new_rows = []
    client = cluster = None
    from .report import source_commit
    writer = RowWriter(rows_path, build=source_commit())
    try:
        client, cluster = make_client(scheduler, workers, security, connect_timeout)
        threads = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
        worker_count = len(client.scheduler_info()["workers"])
        stream.write("study %s: %d tasks, %d already done, %d to run on %d Dask worker(s)%s\n"
                     % (study["name"], len(tasks), len(tasks) - len(todo), len(todo), worker_count,
                        " at " + scheduler if scheduler else " (local cluster)"))
        progress = Progress(len(tasks), len(tasks) - len(todo), stream)
        # References first (the measurements wait for them), then the rest, larger runs first.
        queue = [t for t in todo if t.kind.value == "reference"]
        queue += sorted((t for t in todo if t.kind.value != "reference"), key=expected_cost, reverse=True)
        queue.reverse()  # popped from the end
        window = max(MIN_WINDOW, WINDOW_PER_WORKER * threads)
        futures = {}
        pending = as_completed()

        def submit(task):
            wire = kind.wire(task, bin_dir)
            reference = references.get(task.settings.get("reference")) if wire.get("needs_reference") else None
            future = client.submit(kind.run, wire, reference, key="%s-%s" % (task.kind.value, task.id),
                                   pure=False, retries=TASK_RETRIES)
            if task.kind.value == "reference":
                references[task.label] = future
            futures[future] = task
            pending.add(future)

        while queue and len(futures) < window:
            submit(queue.pop())
        # SIGINT and SIGTERM stop the study between rows: polled, because a wait inside Dask's
        # client does not always let Python's KeyboardInterrupt through.
        while futures and not stop:
            for future in pending.next_batch(block=False):
                task = futures.pop(future)
                try:
                    row = future.result()
                except Exception as error:  # the task could not run at all (e.g. its workers kept dying)
                    row = _failed_row(task, error)
                row["workers"] = worker_count
                writer.write(row)
                new_rows.append(row)
                progress.update(row)
                if task.kind.value == "reference":
                    references[task.label] = row
                if queue and not stop:
                    submit(queue.pop())
            time.sleep(0.05)
        if stop:
            client.cancel(list(futures))
    finally:
        writer.close()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
        for number, handler in handlers.items():
            signal.signal(number, handler)
        if stop:
            raise KeyboardInterrupt(stop[0])
    rows = previous + new_rows
    wall = time.monotonic() - wall_start
    ids = {t.id for t in tasks}
    counts = {}
    for row in rows:
        if row["task_id"] in ids:
            counts[row.get("outcome", "failed")] = counts.get(row.get("outcome", "failed"), 0) + 1
    cpu = sum(row.get("process_cpu_s", 0.0) or 0.0 for row in new_rows)
    summary = ("study %s: %d tasks: %s; %d run now (%d resumed from earlier rows) in %s wall, %s CPU on %d worker(s); "
               "rows %s" % (study["name"], len(tasks), ", ".join("%d %s" % (n, k) for k, n in sorted(counts.items())),
                            len(new_rows), len(tasks) - len(todo), duration_text(wall), duration_text(cpu),
                            worker_count, rows_path))
    return rows, summary

#!/usr/bin/python3
"""What a study costs at scale, measured here: the random-cart study's rate per core, its task-size
spread, the runner's overhead per task (the supervisor process, Dask's scheduling), and from them
the expected wall time of the 100 000-random-cart study (bench/studies/random_carts.yaml with
count 100000: 300 000 tasks) on 10, 100 and 1000 workers (docs/studies.md, "Scale on paper").

    /usr/bin/python3 bench/study_scale.py [--carts 300] [--workers 2] [--bin-dir DIR]

Prints numbers only; asserts nothing. It runs the shipped study with `count` set to --carts (into
a temporary directory), then times the supervisor of one task around /bin/true and the Dask
scheduler's round trip of no-op tasks on a local cluster."""
import argparse
import json
import logging
import os
import statistics
import subprocess
import sys
import tempfile
import time

REPOSITORY = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(REPOSITORY, "src"))

from birkhoff_cart_study.task_runner import Supervised, SupervisorProcess  # noqa: E402

FULL_CARTS = 100000  # the study the projection is for
INTEGRATORS = 3      # random_carts.yaml runs each cart with three integrators


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def run_study(carts, workers, bin_dir, directory):
    with open(os.path.join(REPOSITORY, "bench", "studies", "random_carts.yaml")) as f:
        text = f.read().replace("count: 1000,", "count: %d," % carts)
    study = os.path.join(directory, "random_carts_scale.yaml")
    with open(study, "w") as f:
        f.write(text)
    command = [sys.executable, "-m", "birkhoff_cart_study", study, "--workers", str(workers), "--output-dir",
               os.path.join(directory, "out")] + (["--bin-dir", bin_dir] if bin_dir else [])
    start = time.monotonic()
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                            env=dict(os.environ, PYTHONPATH=os.path.join(REPOSITORY, "src")))
    wall = time.monotonic() - start
    if result.returncode not in (0, 1):
        sys.exit("the study failed:\n" + result.stderr[-2000:])
    with open(os.path.join(directory, "out", "rows.jsonl")) as f:
        rows = [json.loads(line) for line in f]
    return rows, wall, result.stdout.strip()


def supervisor_cost(count=40):
    """[s] of wall time per task that the supervisor adds around /bin/true: (a fresh supervisor
    per task, one reused as a worker thread reuses its own)."""
    costs = []
    for pool in (None, {}):
        start = time.monotonic()
        for _ in range(count):
            with Supervised(["/bin/true"], {"scene.yaml": "x" * 4000}, 10.0, cancelled=lambda: False, pool=pool):
                pass
        costs.append((time.monotonic() - start) / count)
        for state in (pool or {}).values():
            SupervisorProcess(state).close()
    return costs


def no_op(x):
    return x


def scheduler_cost(workers, count=3000):
    """[s] of wall time per no-op task through a local cluster's scheduler and workers."""
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None, worker_dashboard_address="127.0.0.1:0",
                           scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=logging.ERROR)
    client = Client(cluster)
    try:
        client.gather(client.map(no_op, range(100), pure=False))  # warm up
        start = time.monotonic()
        client.gather(client.map(no_op, range(count), pure=False))
        return (time.monotonic() - start) / count
    finally:
        client.close()
        cluster.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--carts", type=int, default=300)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--bin-dir")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="study_scale_") as directory:
        rows, wall, summary = run_study(args.carts, args.workers, args.bin_dir, directory)
    cpu = [r.get("process_cpu_s") or 0.0 for r in rows]
    process_wall = [r.get("process_wall_s") or 0.0 for r in rows]
    tasks = len(rows)
    busy = args.workers * wall
    per_task_overhead = max(0.0, busy - sum(process_wall)) / tasks
    supervisor = supervisor_cost()
    scheduler = scheduler_cost(args.workers)
    load = os.getloadavg()[0]
    print("machine: %d cores, load average %.1f when done" % (os.cpu_count(), load))
    print("random-cart study, %d carts × %d integrators = %d tasks on %d local workers: %.1f s wall, %.2f tasks/s"
          % (args.carts, INTEGRATORS, tasks, args.workers, wall, tasks / wall))
    print("  %s" % summary)
    print("task CPU [ms]: mean %.1f, median %.1f, p90 %.1f, p99 %.1f, max %.1f (process wall: mean %.1f, max %.1f)"
          % tuple(1e3 * x for x in (statistics.mean(cpu), statistics.median(cpu), percentile(cpu, 0.9),
                                    percentile(cpu, 0.99), max(cpu), statistics.mean(process_wall), max(process_wall))))
    print("rate per core: %.1f tasks per CPU-second of the engine; %.2f tasks per worker-second all told"
          % (1.0 / statistics.mean(cpu), tasks / busy))
    print("runner overhead per task on a worker: %.1f ms (worker time not in the task's process); a task of "
          "/bin/true under the thread's supervisor: %.1f ms (%.1f ms with a supervisor started for it); Dask's "
          "scheduling of a no-op task: %.2f ms" % (1e3 * per_task_overhead, 1e3 * supervisor[1], 1e3 * supervisor[0],
                                                   1e3 * scheduler))
    full = FULL_CARTS * INTEGRATORS
    per_task = statistics.mean(process_wall) + per_task_overhead
    for workers in (10, 100, 1000):
        compute = full * per_task / workers
        scheduler_bound = full * scheduler
        print("%d random carts (%d tasks) on %4d workers: %.0f s of compute per worker, scheduler bound %.0f s → "
              "about %.0f s wall" % (FULL_CARTS, full, workers, compute, scheduler_bound, max(compute, scheduler_bound)))


if __name__ == "__main__":
    main()

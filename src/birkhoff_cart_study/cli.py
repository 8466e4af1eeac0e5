"""study: run a study file on Dask distributed and write its rows, tables and plots (docs/studies.md).

    python3 -m birkhoff_cart_study STUDY.yaml [--smoke] [--workers N] [--output-dir DIR]
                                   [--report PAGE.md] [--report-only] [--fresh] [--retry-failed]
                                   [--scheduler tcp://HOST:PORT | tls://HOST:PORT --tls-ca-file CA
                                    --tls-cert CERT --tls-key KEY]
    (rosrun birkhoff_cart study ... is the same command)

Without --scheduler an embedded LocalCluster on 127.0.0.1 runs one single-threaded worker per
core. Rows go to DIR/rows.jsonl as tasks finish; the same command again runs only the tasks
without a row. Exit status: 0 every task ok (or refused, where the study allows it) and every goal
judged; 1 some task failed or timed out; 2 a bad study file or bad arguments (nothing ran); 3 every
task ran but a reference could not resolve some goal (no verdict for it; the report says which
and why); 130 (SIGINT) or 143 (SIGTERM) interrupted: the finished rows are kept and the running
tasks' processes stopped."""
import argparse
import fcntl
import os
import re
import sys

from .engine import ROWS_FILE, SchedulerUnreachable, latest_rows, read_rows, run_study
from .limits import StudyError, quoted
from .registry import read_registry
from .report import write_report
from .study import load_study

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_UNRESOLVED = 0, 1, 2, 3
SCHEDULER = re.compile(r"^(tcp|tls)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9][A-Za-z0-9.-]{0,252}):([0-9]{1,5})$")
PACKAGE_ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


class UsageError(Exception):
    """Bad arguments: exit 2 with one line, nothing run."""


def _roots():
    """The repository (src/birkhoff_cart_study is two levels below it) or the install space's
    share/birkhoff_cart (python/birkhoff_cart_study), then the sourced workspaces."""
    roots = [PACKAGE_ROOT]
    roots += [os.path.join(p, "share", "birkhoff_cart") for p in os.environ.get("CMAKE_PREFIX_PATH", "").split(":") if p]
    return roots


def find_bin_dir(given):
    """Where work_precision and cart_simulate are: --bin-dir, $BIRKHOFF_CART_BIN_DIR, beside the
    command (install space), the repository's .ws/devel, or the sourced workspaces."""
    options = [given, os.environ.get("BIRKHOFF_CART_BIN_DIR"), os.path.dirname(os.path.abspath(sys.argv[0])),
               os.path.join(PACKAGE_ROOT, ".ws", "devel", "lib", "birkhoff_cart")]
    options += [os.path.join(p, "lib", "birkhoff_cart") for p in os.environ.get("CMAKE_PREFIX_PATH", "").split(":") if p]
    for option in options:
        if option and all(os.access(os.path.join(option, name), os.X_OK) for name in ("work_precision", "cart_simulate")):
            return os.path.abspath(option)
    return None


def find_scene_dir():
    for root in _roots():
        path = os.path.join(root, "config", "scenes")
        if os.path.isdir(path):
            return path
    return "config/scenes"


def parse_arguments(argv):
    parser = argparse.ArgumentParser(prog="study", description=__doc__.split("\n\n")[0])
    parser.add_argument("study_file")
    parser.add_argument("--smoke", action="store_true",
                        help="the study at its smoke size: a few tasks of every experiment (CI runs every shipped study so)")
    parser.add_argument("--scheduler", help="a Dask scheduler: tcp://HOST:PORT, or tls://HOST:PORT with the --tls-* files "
                                            "(default: a local cluster on 127.0.0.1)")
    parser.add_argument("--tls-ca-file", help="tls://: the certificate authority's certificate (PEM)")
    parser.add_argument("--tls-cert", help="tls://: this client's certificate (PEM)")
    parser.add_argument("--tls-key", help="tls://: this client's private key (PEM)")
    parser.add_argument("--scheduler-timeout", type=float, default=10.0,
                        help="seconds to reach the scheduler before giving up (default 10)")
    parser.add_argument("--workers", type=int, help="local cluster: worker processes (default: one per core)")
    parser.add_argument("--output-dir", help="where rows.jsonl goes (default: study_results/<name>, "
                                             "with --smoke study_results/<name>_smoke)")
    parser.add_argument("--report", help="the results page to write (default: <output dir>/results.md)")
    parser.add_argument("--report-only", action="store_true", help="tables and plots from the rows, nothing run")
    parser.add_argument("--bin-dir", help="the directory of work_precision and cart_simulate")
    parser.add_argument("--report-command", help="the command the report names for regenerating it (default: this one)")
    parser.add_argument("--retry-failed", action="store_true", help="also rerun the tasks whose row failed or timed out")
    parser.add_argument("--fresh", action="store_true", help="start over: the earlier rows are moved to rows.jsonl.old")
    return parser, parser.parse_args(argv)


def scheduler_security(args):
    """(address or None, distributed.Security or None); UsageError for a bad address or TLS files."""
    if args.scheduler is None:
        if args.tls_ca_file or args.tls_cert or args.tls_key:
            raise UsageError("--tls-ca-file, --tls-cert and --tls-key go with --scheduler tls://HOST:PORT")
        return None, None
    match = SCHEDULER.match(args.scheduler)
    if match is None or not 1 <= int(match.group(3)) <= 65535:
        raise UsageError("--scheduler must be tcp://HOST:PORT or tls://HOST:PORT (port 1-65535), got %s"
                         % quoted(args.scheduler))
    files = {"--tls-ca-file": args.tls_ca_file, "--tls-cert": args.tls_cert, "--tls-key": args.tls_key}
    if match.group(1) == "tcp":
        if any(files.values()):
            raise UsageError("--tls-* files need --scheduler tls://HOST:PORT, got a tcp:// address")
        return args.scheduler, None
    missing = [option for option, value in files.items() if not value]
    if missing:
        raise UsageError("--scheduler tls://... needs %s (certificates: docs/studies.md, 'On a cluster')" % ", ".join(missing))
    for option, value in files.items():
        if not os.path.isfile(value):
            raise UsageError("%s: no such file %s" % (option, quoted(value, 200)))
    from distributed.security import Security
    return args.scheduler, Security(tls_ca_file=args.tls_ca_file, tls_client_cert=args.tls_cert,
                                    tls_client_key=args.tls_key, require_encryption=True)


class OutputLock:
    """The output directory's lock (DIR/.lock, flock): taken before anything in DIR is moved or
    written, held until the runner ends; a second runner on the same directory is refused."""

    def __init__(self, directory):
        os.makedirs(directory, exist_ok=True)
        self.file = open(os.path.join(directory, ".lock"), "w")
        try:
            fcntl.flock(self.file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.file.close()
            raise UsageError("another study runner is writing %s; wait for it or stop it first" % directory)


def main(argv=None):
    parser, args = parse_arguments(sys.argv[1:] if argv is None else argv)
    try:
        if args.workers is not None and args.workers < 1:
            raise UsageError("--workers must be at least 1, got %d" % args.workers)
        if not args.scheduler_timeout > 0:
            raise UsageError("--scheduler-timeout must be > 0")
        scheduler, security = scheduler_security(args)
        bin_dir = find_bin_dir(args.bin_dir)
        if bin_dir is None:
            raise UsageError("cannot find work_precision and cart_simulate (build the package, source its setup.bash, "
                             "or give --bin-dir)")
        try:
            registry = read_registry(os.path.join(bin_dir, "cart_simulate"))
        except (OSError, ValueError) as error:
            raise UsageError(str(error))
        study, tasks = load_study(args.study_file, registry, find_scene_dir(), smoke=args.smoke)
    except (UsageError, StudyError) as error:
        print("study: %s" % error, file=sys.stderr)
        return EXIT_USAGE
    output_dir = args.output_dir or os.path.join("study_results", study["name"] + ("_smoke" if args.smoke else ""))
    page = args.report or os.path.join(output_dir, "results.md")
    command = args.report_command or "rosrun birkhoff_cart study " + " ".join(sys.argv[1:] if argv is None else argv)
    rows_path = os.path.join(output_dir, ROWS_FILE)
    ids = {t.id for t in tasks}
    if args.report_only:
        rows = [r for r in latest_rows(read_rows(rows_path)) if r.get("task_id") in ids]
        summary = "report only: %d of %d tasks have rows" % (len(rows), len(tasks))
    else:
        try:
            lock = OutputLock(output_dir)  # before anything in the directory moves
        except UsageError as error:
            print("study: %s" % error, file=sys.stderr)
            return EXIT_USAGE
        if args.fresh and os.path.exists(rows_path):
            os.replace(rows_path, rows_path + ".old")
        try:
            rows, summary = run_study(study, tasks, output_dir, bin_dir, scheduler, args.workers,
                                      retry_failed=args.retry_failed, security=security,
                                      connect_timeout=args.scheduler_timeout)
        except KeyboardInterrupt as interrupt:
            number = interrupt.args[0] if interrupt.args else 2
            print("study: interrupted; the finished rows are in %s (the same command resumes)" % rows_path, file=sys.stderr)
            return 128 + number
        except SchedulerUnreachable as error:
            print("study: %s" % error, file=sys.stderr)
            return EXIT_USAGE
        finally:
            lock.file.close()
        rows = [r for r in rows if r.get("task_id") in ids]
    unresolved = write_report(study, rows, page, command, summary)
    if unresolved:
        summary += "; %d goal%s without a verdict: the reference does not resolve %s (%s)" % (
            len(unresolved), "" if len(unresolved) == 1 else "s", "it" if len(unresolved) == 1 else "them",
            unresolved[0] + ("; …" if len(unresolved) > 1 else ""))
    print("study: wrote %s" % page, file=sys.stderr)
    print(summary)
    failed = sum(1 for r in rows if r.get("outcome") in ("failed", "timeout"))
    if failed or len(rows) < len(tasks):
        return EXIT_FAILED
    return EXIT_UNRESOLVED if unresolved else EXIT_OK

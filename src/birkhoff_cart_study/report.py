"""The results page of a study, from its rows: one code path, whether the rows came from one machine
or a hundred. The page records the command, the date, the source commit, the machine, its load and
the workers, so every number in it says where it came from; the study kind writes its own sections (kinds/*.py:
report) and names the goals its references cannot resolve."""
import datetime
import os
import platform
import subprocess

from .kinds import module_of


def machine():
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return "%s, %d cores, %s" % (model, os.cpu_count(), platform.system())


# Files a report run itself writes or moves (the page, its plots, the rows): not "changes" of the source.
_OUTPUT_SUFFIXES = (".md", ".png", ".jsonl", ".jsonl.old")


def source_commit(directory=None):
    """The commit of the source tree this runner is part of (`git rev-parse HEAD`), with the number of
    tracked source files changed since, if any (pages, plots and rows do not count); "—" outside a
    git checkout (an installed runner)."""
    directory = directory or os.path.dirname(os.path.abspath(__file__))
    try:
        head = subprocess.run(["git", "-C", directory, "rev-parse", "HEAD"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True, timeout=30)
        if head.returncode != 0 or not head.stdout.strip():
            return "—"
        status = subprocess.run(["git", "-C", directory, "status", "--porcelain", "--untracked-files=no"],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return "—"
    changed = [line[3:] for line in status.stdout.splitlines() if line[3:] and not line[3:].endswith(_OUTPUT_SUFFIXES)]
    commit = "`%s`" % head.stdout.strip()
    return commit + (" with changes to %d source file%s" % (len(changed), "" if len(changed) == 1 else "s")
                     if changed else "")


def other_builds(rows):
    """Which experiments' rows a build other than most rows' measured (each row carries the source
    commit that measured it, `build`; rows written before rows carried one say nothing): "none", or
    each such experiment with its rows' commits. Rows measured before the right-hand sides took their
    elementary functions from SLEEF (CHANGELOG 0.6.0) reproduce on their own CPU only
    (docs/developing.md, "Figures that hold on every machine")."""
    unrecorded = "an earlier build that recorded none"
    counts = {}
    for row in rows:
        build = row.get("build", unrecorded)
        counts[build] = counts.get(build, 0) + 1
    if len(counts) <= 1:
        return "none"
    most = max(counts, key=counts.get)
    others = {}
    for row in rows:
        build = row.get("build", unrecorded)
        if build != most:
            others.setdefault(row.get("label", "?"), set()).add(build)
    return "; ".join("%s: %s (rows measured with glibc's libm reproduce on their own CPU only)"
                     % (label, ", ".join(sorted(builds))) if builds == {unrecorded}
                     else "%s: %s" % (label, ", ".join(sorted(builds))) for label, builds in sorted(others.items()))


def stage_evaluation():
    """How the Birkhoffian collocation members evaluate their stages in the runs of this machine
    (docs/integrators.md, "Stage evaluation"): BIRKHOFF_CART_STAGE_EVALUATION when set, else
    "vector" where the CPU has AVX, "scalar" otherwise. The two give the same bits (SLEEF's
    deterministic functions on both), so the path is recorded for the speed only."""
    chosen = os.environ.get("BIRKHOFF_CART_STAGE_EVALUATION", "")
    if chosen in ("scalar", "vector"):
        return chosen
    try:
        with open("/proc/cpuinfo") as f:
            flags = next((line.split(":", 1)[1].split() for line in f if line.startswith("flags")), [])
    except OSError:
        flags = []
    return "vector" if "avx" in flags else "scalar"


def _cell(text):
    return str(text).replace("|", "/").replace("\n", " ")


def _number(value):
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def write_report(study, rows, page_path, command, summary):
    """Writes the results page (markdown) and its plots beside it (<page stem>_*.png); returns the
    goals without a verdict (one line each: what and why)."""
    stem = os.path.basename(os.path.splitext(page_path)[0])
    directory = os.path.dirname(os.path.abspath(page_path))
    os.makedirs(directory, exist_ok=True)
    loads = sorted(x for x in (_number(r.get("load_average_1min")) for r in rows) if x is not None)
    workers = sorted({r.get("workers") for r in rows if isinstance(r.get("workers"), int)})
    cpu_total = sum(_number(r.get("process_cpu_s")) or 0.0 for r in rows)
    sections, unresolved = module_of(study["kind"]).report(study, rows, directory, stem)
    out = ["# Results: %s" % study["name"], "",
           "Generated by the study runner from %d rows; do not edit by hand. Regenerate with:" % len(rows), "",
           "    %s" % command.replace("\n", " "), "",
           "| | |", "|---|---|",
           "| written | %s |" % datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "| source commit | %s |" % source_commit(),
           "| machine | %s |" % _cell(machine()),
           "| stage evaluation | %s |" % stage_evaluation(),
           "| rows of other builds | %s |" % _cell(other_builds(rows)),
           "| Dask workers | %s |" % ", ".join(str(w) for w in workers),
           "| load average while running (1 min, over the tasks) | %s |" % (
               "%.1f–%.1f (median %.1f)" % (loads[0], loads[-1], loads[len(loads) // 2]) if loads else "—"),
           "| process CPU time, all tasks | %.1f s |" % cpu_total,
           "| last run | %s |" % _cell(summary), ""]
    if study.get("description", "").strip():
        out += [study["description"].strip(), ""]
    if unresolved:
        out += ["**No verdict for %d goal%s: the reference does not resolve %s** (a reference judges a goal only where "
                "it and its independent check agree to a tenth of it):" % (len(unresolved), "" if len(unresolved) == 1
                                                                           else "s", "it" if len(unresolved) == 1
                                                                           else "them"), ""]
        out += ["- %s" % _cell(line) for line in unresolved[:50]]
        if len(unresolved) > 50:
            out.append("- … and %d more" % (len(unresolved) - 50))
        out.append("")
    if study["kind"] == "work_precision":
        out += ["Times are each run's median process CPU time over its repetitions (fair within one study: "
                "every task runs single-threaded in its own process); ratios are peer CPU / best Birkhoffian CPU, "
                "so a ratio above 1 means the Birkhoffian member is cheaper. Errors are deterministic and do not "
                "depend on the number of workers.", ""]
    out += sections
    failed = [r for r in rows if r.get("outcome", "failed") in ("failed", "timeout") and r.get("type") != "simulate"]
    if failed:
        out += ["## Failed tasks", "", "| task | type | method | outcome | reason |", "|---|---|---|---|---|"]
        for r in failed:
            out.append("| %s | %s | %s | %s | %s |" % (_cell(r.get("label", "")), _cell(r.get("type", "")),
                                                       _cell(r.get("method", "")), _cell(r.get("outcome", "failed")),
                                                       _cell(r.get("reason") or "")[:200]))
        out.append("")
    with open(page_path, "w") as f:
        f.write("\n".join(out))
    return unresolved

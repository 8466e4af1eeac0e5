#!/usr/bin/env python3
"""The price table of `work_precision --price` in instructions per evaluation (callgrind), which the
load of a shared machine does not move (docs/benchmarks.md, "The price of an evaluation").

    /usr/bin/python3 bench/price_callgrind.py [--ws .ws] [--scene NAME] [--top N] [--out DIR]

Runs `work_precision --price --callgrind` under valgrind's callgrind, collecting only inside
price_region() (one cell's run) and dumping a profile after each, then prints every cell's
instructions / right-hand-side evaluations with the ratios controlled / fixed and price / bare rhs.
--top N also prints each cell's N most expensive functions (inclusive of nothing: self cost) with
their share. Exit status: 0 done; 1 valgrind or the benchmark failed.
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

ROW = re.compile(r"^  (\S+)\s+(\S+)\s+(\S+)\s+(\d+)\s+(\d+)\s+(\d+)\s")


def dump_instructions(path):
    """Total instructions (Ir) of one callgrind dump."""
    for line in path.read_text().splitlines():
        if line.startswith("summary:") or line.startswith("totals:"):
            return int(line.split()[1])
    raise RuntimeError(f"{path}: no totals line")


def top_functions(path, count):
    """The `count` functions with the largest self cost in one dump, as (share, name)."""
    out = subprocess.run(["callgrind_annotate", "--inclusive=no", "--threshold=100", str(path)], capture_output=True,
                         text=True, check=True).stdout
    total = dump_instructions(path)
    rows = []
    for line in out.splitlines():
        match = re.match(r"^\s*([\d,]+)\s+\([^)]*\)\s+(.*)$", line)
        if match and "PROGRAM TOTALS" not in line:
            share = int(match.group(1).replace(",", "")) / total
            if share < 0.999:  # the callers of the region (main, run_price, ...) show the whole run
                rows.append((share, match.group(2).strip()))
        if len(rows) >= count:
            break
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ws", default=".ws", help="the catkin workspace with devel/lib/birkhoff_cart")
    parser.add_argument("--scene", default="", help="one scene only (default: all four)")
    parser.add_argument("--top", type=int, default=0, help="also print each cell's N costliest functions")
    parser.add_argument("--out", default="", help="keep the callgrind dumps in this directory")
    args = parser.parse_args()
    binary = pathlib.Path(args.ws) / "devel" / "lib" / "birkhoff_cart" / "work_precision"
    out_dir = pathlib.Path(args.out or tempfile.mkdtemp(prefix="price_callgrind_"))
    out_dir.mkdir(parents=True, exist_ok=True)
    for old in out_dir.glob("callgrind.out*"):
        old.unlink()
    command = ["valgrind", "--tool=callgrind", "--toggle-collect=*price_region*", "--dump-after=*work_precision::price_region*",
               f"--callgrind-out-file={out_dir / 'callgrind.out'}", str(binary), "--price", "--callgrind"]
    if args.scene:
        command += ["--scene", args.scene]
    run = subprocess.run(command, capture_output=True, text=True)
    if run.returncode != 0:
        sys.stderr.write(run.stdout + run.stderr)
        return 1
    dumps = sorted((p for p in out_dir.glob("callgrind.out.*") if p.suffix[1:].isdigit()),
                   key=lambda p: int(p.suffix[1:]))
    skipped = 0  # dumps of runs that failed part way
    scenes = []  # [header line, [(method, control, setting, evaluations, Ir/evaluation, dump) or refused line]]
    for line in run.stdout.splitlines():
        match = ROW.match(line.replace("bare rhs", "bare_rhs", 1))
        if match:
            method, control, setting, _steps, _rejected, evaluations = match.groups()
            index = sum(isinstance(r, tuple) for _, rows in scenes for r in rows) + skipped
            if len(dumps) <= index:
                sys.stderr.write("price_callgrind: fewer profile dumps than cells\n")
                return 1
            dump = dumps[index]
            scenes[-1][1].append((method, control, setting, int(evaluations),
                                  dump_instructions(dump) / max(1, int(evaluations)), dump))
        elif "  refused: " in line:
            scenes[-1][1].append(line)
        elif "  failed part way: " in line:  # its run started in price_region(): a dump of its own
            skipped += 1
            scenes[-1][1].append(line)
        elif line and not line.startswith("Price") and not line.startswith("  method"):
            scenes.append((line, []))
    print("Price of a right-hand-side evaluation in instructions (callgrind Ir / evaluations), one run per cell")
    for header, rows in scenes:
        print(header)
        print(f"  {'method':<16} {'control':<10} {'setting':<12} {'rhs evals':>10} {'Ir/eval':>10} "
              f"{'/fixed':>8} {'/(z,y)':>8} {'/z':>8}")
        cells = {(r[0], r[1], r[2]): r[4] for r in rows if isinstance(r, tuple)}
        by_control = {(r[0], r[1]): r[4] for r in rows if isinstance(r, tuple)}
        bare = cells.get(("bare_rhs", "-", "rates(z,y)"), float("nan"))
        bare_birkhoffian = cells.get(("bare_rhs", "-", "rates(z)"), float("nan"))
        for row in rows:
            if not isinstance(row, tuple):
                print(row)
                continue
            method, control, setting, evaluations, price, dump = row
            fixed = by_control.get((method, "fixed")) if control in ("adaptive", "reversible", "fixed") else None
            print(f"  {method.replace('_rhs', ' rhs'):<16} {control:<10} {setting:<12} {evaluations:>10} "
                  f"{price:>10.0f} {(price / fixed if fixed else float('nan')):>8.2f} {price / bare:>8.2f} "
                  f"{price / bare_birkhoffian:>8.2f}")
            for share, name in (top_functions(dump, args.top) if args.top else []):
                print(f"      {100 * share:5.1f} %  {name[:110]}")
    print(f"(callgrind dumps in {out_dir})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

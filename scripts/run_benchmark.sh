#!/usr/bin/env bash
# Work–precision benchmark (issues 6 and 11; docs/benchmarks.md): build, run the ROS-free
# work_precision executable from the repository, then plot and tabulate with Debian's
# python3-matplotlib.
#
# Usage: scripts/run_benchmark.sh [--quick] [more work_precision options, e.g. --only SCENE]
#   default: 17 min CPU; 53 min 42 s wall at load average 9–15 on the shared 2-core machine
#            (measured 23 Nov 2026); writes bench/results/*.csv, *.png, work_precision.md
#   --quick: smoke run (3 repetitions, jackknife_whirl 100 s, 1–3 settings per method): 47 s wall
#            with the plots, 6.1 s CPU, at load 11.6 (measured with `time`), into /tmp/birkhoff_cart_bench_quick unless
#            --output-dir is given
# Environment: BIRKHOFF_CART_WORKSPACE = an already-built catkin workspace to use instead of
#              running scripts/setup.sh (which builds .ws/).
set -euo pipefail
# shellcheck source=scripts/workspace.sh
source "$(dirname "${BASH_SOURCE[0]}")/workspace.sh"  # → $repo, $workspace (set up and built)
binary="$workspace/devel/lib/birkhoff_cart/work_precision"
if [ ! -x "$binary" ]; then
  echo "run_benchmark.sh: $binary not built" >&2
  exit 1
fi

output_dir="$repo/bench/results"
arguments=("$@")
for argument in "$@"; do
  if [ "$argument" = "--quick" ]; then output_dir=/tmp/birkhoff_cart_bench_quick; fi
done
for ((i = 0; i < ${#arguments[@]}; ++i)); do
  if [ "${arguments[$i]}" = "--output-dir" ]; then output_dir="${arguments[$((i + 1))]}"; fi
done
mkdir -p "$output_dir"

cd "$repo"
echo "load before: $(cat /proc/loadavg)"
start=$(date +%s)
"$binary" --output-dir "$output_dir" "$@"
echo "load after:  $(cat /proc/loadavg); work_precision took $(($(date +%s) - start)) s wall"
/usr/bin/python3 "$repo/bench/bench_plot.py" "$output_dir"

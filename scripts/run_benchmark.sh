#!/usr/bin/env bash
# The work–precision benchmark as a study (docs/studies.md): build, then run
# bench/studies/work_precision.yaml with the study runner on a local Dask cluster (one worker per
# core) and write docs/results.md with its plots. Its rows go to bench/results/work_precision/;
# running it again resumes (only tasks without a row run); --fresh starts over.
#
# Usage: scripts/run_benchmark.sh [--quick] [more study options, e.g. --workers 1, --scheduler tcp://HOST:PORT, --fresh]
#   --quick: bench/studies/work_precision_quick.yaml into ${TMPDIR:-/tmp}/birkhoff_cart_bench_quick/ (seconds)
# Environment: BIRKHOFF_CART_WORKSPACE = an already-built catkin workspace to use instead of
#              running scripts/setup.sh (which builds .ws/).
set -euo pipefail
# shellcheck source=scripts/workspace.sh
source "$(dirname "${BASH_SOURCE[0]}")/workspace.sh"  # → $repo, $workspace (set up and built)
study="$repo/bench/studies/work_precision.yaml"
command="bash scripts/run_benchmark.sh $*"
output_dir="$repo/bench/results/work_precision"
report="$repo/docs/results.md"
arguments=()
for argument in "$@"; do
  if [ "$argument" = "--quick" ]; then
    study="$repo/bench/studies/work_precision_quick.yaml"
    output_dir="${TMPDIR:-/tmp}/birkhoff_cart_bench_quick"
    report="$output_dir/results.md"
  else
    arguments+=("$argument")
  fi
done
cd "$repo"
exec /usr/bin/python3 "$repo/scripts/study" "$study" --output-dir "$output_dir" --report "$report" \
  --bin-dir "$workspace/devel/lib/birkhoff_cart" --report-command "${command% }" ${arguments[@]+"${arguments[@]}"}

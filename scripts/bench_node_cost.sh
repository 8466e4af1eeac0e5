#!/usr/bin/env bash
# Node cost (issue 6, docs/benchmarks.md "Node cost"): cart_sim on the default scene (h = 1 ms,
# 100 Hz publishing) in fast mode (300 s of scene time, three times each) without and with bag recording (real-time factor from the node's
# own summary), and in real-time mode (CPU share of one core from /proc/<pid>/stat utime + stime
# over a 15 s window of wall time). Each case twice: the default scene as shipped (it carries a
# lockstep dopri5 shadow reference at tolerance 1e-12) and the same scene without the reference. Starts its own roscore on a private port and stops only the
# processes it started.
#
# Usage: scripts/bench_node_cost.sh [WORKSPACE]     (default .ws; must have cart_sim built)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
workspace="${1:-$repo/.ws}"
export PATH="/usr/bin:/bin:$PATH"
set +u
# shellcheck disable=SC1091
source "$workspace/devel/setup.bash"
set -u
# A free port (as scripts/run_main.sh): a random one could be another master's, which would then
# answer below and get our /use_sim_time and nodes.
port="$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://localhost:$port"
export ROS_LOG_DIR="$(mktemp -d /tmp/birkhoff_cart_node_cost.XXXXXX)"
scene="$repo/config/scenes/default.yaml"
node="$workspace/devel/lib/birkhoff_cart/cart_sim"  # not rosrun: workspaces inside the repository hold more than one cart_sim
work="$ROS_LOG_DIR"
clock_ticks=$(getconf CLK_TCK)

roscore -p "$port" > "$work/roscore.log" 2>&1 &
roscore_pid=$!
trap 'kill "$roscore_pid" 2>/dev/null || true; wait "$roscore_pid" 2>/dev/null || true' EXIT
for _ in $(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
if ! kill -0 "$roscore_pid" 2>/dev/null; then
  echo "bench_node_cost.sh: roscore on port $port did not start (see $work/roscore.log)" >&2
  exit 1
fi
rosparam set /use_sim_time true

# The default scene without its shadow reference (everything else identical).
scene_without_reference="$work/default_without_reference.yaml"
awk '/^reference:/ {exit} {print}' "$scene" > "$scene_without_reference"
printf 'reference:\n  kind: none\n' >> "$scene_without_reference"

cpu_ticks() {  # utime + stime of a process [clock ticks]
  awk '{print $14 + $15}' "/proc/$1/stat"
}

clear_node_parameters() {  # private parameters outlive the node on the master: a run must not inherit ~bag_path
  rosparam delete /cart_sim > /dev/null 2>&1 || true
}

fast_run() {  # $1 label, $2 scene, $3 extra parameters
  local summary="$work/summary_$1.txt"
  clear_node_parameters
  # shellcheck disable=SC2086
  "$node" __name:=cart_sim _scene:="$2" _step_size:=0.001 _fast:=true \
    _publish_rate:=100 _duration:=300 _summary_path:="$summary" $3 > "$work/$1.log" 2>&1
  echo "fast mode, $1: $(grep -o 'wall time [^)]*)[^.]*real-time factor [0-9.e+]*' "$summary")"
  grep -o 'Bag: .*' "$summary" || true
}

real_time_run() {  # $1 label, $2 scene: CPU share over 15 s of wall time after a 3 s start-up
  clear_node_parameters
  "$node" __name:=cart_sim _scene:="$2" _step_size:=0.001 _fast:=false \
    _publish_rate:=100 _duration:=25 > "$work/$1.log" 2>&1 &
  local node_pid=$!
  sleep 3
  local ticks0 ticks1 wall0 wall1
  ticks0=$(cpu_ticks "$node_pid"); wall0=$(date +%s.%N)
  sleep 15
  ticks1=$(cpu_ticks "$node_pid"); wall1=$(date +%s.%N)
  wait "$node_pid" || true
  awk -v t0="$ticks0" -v t1="$ticks1" -v w0="$wall0" -v w1="$wall1" -v hz="$clock_ticks" -v label="$1" \
    'BEGIN {printf "real-time mode, %s, h = 1 ms, 100 Hz publishing: CPU %.2f s over %.2f s wall = %.1f%% of one core\n", label, (t1 - t0) / hz, w1 - w0, 100 * (t1 - t0) / hz / (w1 - w0)}'
}

echo "load before: $(cat /proc/loadavg)"
for repetition in 1 2 3; do  # 300 s of scene time each; three times, the machine is shared
  fast_run "shipped_no_bag_$repetition" "$scene" ""
  fast_run "shipped_with_bag_$repetition" "$scene" "_bag_path:=$work/shipped.bag"
  fast_run "no_reference_no_bag_$repetition" "$scene_without_reference" ""
  fast_run "no_reference_with_bag_$repetition" "$scene_without_reference" "_bag_path:=$work/no_reference.bag"
done
ls -l "$work"/*.bag | awk '{print "bag " $9 ": " $5 " bytes"}'
real_time_run shipped "$scene"
real_time_run no_reference "$scene_without_reference"
echo "load after:  $(cat /proc/loadavg)"
echo "logs: $work"

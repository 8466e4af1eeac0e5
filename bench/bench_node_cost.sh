#!/usr/bin/env bash
# Node cost (docs/benchmarks.md, "The node's cost"): cart_sim on the default scene with birkhoff2 at h = 1 ms
# (the cheapest Birkhoffian 1 kHz stepping; the scene itself now defaults to birkhoff_gauss4 at 10 ms,
# 100 Hz publishing, its dopri5 shadow reference on) in fast mode for 300 s of scene time, with and
# without the bag, beside cart_simulate on the same scene and duration (the bare core with CSV at
# 100 Hz), three times each; then lockstep with steering_pd_controller (driven.yaml, 60 s at 50 Hz;
# then 600 s without a bag, as two processes and as nodelets in one manager), and real-time mode at 1 kHz (CPU share of one core over 15 s of wall time). Also the default
# scene as shipped (birkhoff_gauss4 at h = 10 ms) with and without the bag beside cart_simulate,
# and the bag uncompressed (~bag_compression none) once.
# Ratios: scene time / wall time (the node's from its own summary: its time loop), and CPU time
# (user + sys of the whole process, all threads) — the machine is shared, so CPU time is the
# steadier measure of cost; node/core = node's cost over cart_simulate's.
# Starts its own roscore on a free port, stops only what it started, removes its scratch directory.
#
# --default-scene-only [N]: only the default scene as shipped with its bag on, beside cart_simulate,
# N times (default 5) in turns (node then core, core then node, ...), so that both see the same load:
# per run the node's loop factor (its summary) and its process's, cart_simulate's (scene time over
# its process's wall time), the CPU time of each per second of scene time, the ratio core/node and
# the load average; then the medians. About 3 s a pair.
#
# Usage: bench/bench_node_cost.sh [--default-scene-only [N]] [WORKSPACE]   (default .ws; must have cart_sim built)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
default_scene_only=0
if [ "${1:-}" = "--default-scene-only" ]; then
  default_scene_only=5
  shift
  if [[ "${1:-}" =~ ^[1-9][0-9]*$ ]]; then default_scene_only="$1"; shift; fi
fi
workspace="${1:-$repo/.ws}"
export PATH="/usr/bin:/bin:$PATH"
set +u
# shellcheck disable=SC1091
source "$workspace/devel/setup.bash"
set -u
port="$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://localhost:$port"
work="$(mktemp -d /tmp/birkhoff_cart_node_cost.XXXXXX)"
export ROS_LOG_DIR="$work/ros_log"
scene="$repo/config/scenes/default.yaml"
bin="$workspace/devel/lib/birkhoff_cart"  # not rosrun: workspaces inside the repository hold more than one build
clock_ticks=$(getconf CLK_TCK)
duration=300

roscore -p "$port" > "$work/roscore.log" 2>&1 &
roscore_pid=$!
cleanup() {
  kill "$roscore_pid" 2>/dev/null || true
  wait "$roscore_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
for _ in $(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
if ! kill -0 "$roscore_pid" 2>/dev/null; then
  echo "bench_node_cost.sh: roscore on port $port did not start" >&2
  exit 1
fi
# rosout reads /use_sim_time once, as it starts, and under sim time subscribes to /clock: every
# /clock the node publishes is then sent to it over TCP (about 2.6 us of the node's time loop per
# instant, and rosout woken 30 000 times a run). The master answers before rosout is up, so set
# /use_sim_time only once rosout subscribes to /rosout (its start is over): no run has that listener.
for _ in $(seq 100); do rostopic info /rosout 2>/dev/null | grep -q '^ \* /rosout ' && break; sleep 0.1; done
rosparam set /use_sim_time true

cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }  # utime + stime [clock ticks]
# CPU time of every thread of process $1 [ns] (schedstat's first field: time on a CPU), exact where
# clock ticks are 10 ms coarse.
cpu_nanoseconds() { cat /proc/"$1"/task/*/schedstat 2>/dev/null | awk '{s += $1} END {printf "%.0f", s}'; }

timed() {  # $1 output file for "wall user sys"; the rest: the command
  local out="$1"; shift
  /usr/bin/time -f "%e %U %S" -o "$out" "$@"
}

stepping="_integrator:=birkhoff2 _step_size:=0.001"      # birkhoff2 at 1 kHz (node)
core_stepping="--integrator birkhoff2 --step 0.001"      # the same for cart_simulate
node_fast() {  # $1 label, $2 extra parameters -> "node_wall node_loop_rtf node_cpu"
  rosparam delete /cart_sim > /dev/null 2>&1 || true
  # shellcheck disable=SC2086
  timed "$work/$1.time" "$bin/cart_sim" __name:=cart_sim _scene:="$scene" $stepping _fast:=true \
    _publish_rate:=100 _duration:=$duration _summary_path:="$work/$1.summary" $2 > "$work/$1.log" 2>&1
  local rtf; rtf=$(grep -o 'real-time factor [0-9.e+]*' "$work/$1.summary" | awk '{print $3}'); rtf="${rtf%.}"
  awk -v rtf="$rtf" '{printf "%s %s %s", $1, rtf, $2 + $3}' "$work/$1.time"
}

core_run() {  # -> "wall cpu"
  # shellcheck disable=SC2086
  timed "$work/core.time" "$bin/cart_simulate" --quiet --scene "$scene" $core_stepping --output-rate 100 \
    --duration $duration --output "$work/core.csv" > /dev/null
  awk '{printf "%s %s", $1, $2 + $3}' "$work/core.time"
}

fast_table() {  # $1 title; three runs of node with bag, without, and cart_simulate
  echo "$1"
  printf "%-4s | %-34s | %-34s | %-22s | %s\n" run "node, bag: wall s (loop x) / CPU s" "node, no bag: wall s (loop x) / CPU s" \
    "cart_simulate: wall / CPU s" "x real time (scene/wall): node bag, core; node/core wall, CPU"
  for repetition in 1 2 3; do
    read -r bag_wall bag_rtf bag_cpu <<< "$(node_fast "bag_$repetition" "_bag_path:=$work/node.bag")"
    read -r nobag_wall nobag_rtf nobag_cpu <<< "$(node_fast "nobag_$repetition" "")"
    read -r core_wall core_cpu <<< "$(core_run)"
    awk -v r="$repetition" -v bw="$bag_wall" -v br="$bag_rtf" -v bc="$bag_cpu" -v nw="$nobag_wall" -v nr="$nobag_rtf" \
      -v nc="$nobag_cpu" -v cw="$core_wall" -v cc="$core_cpu" -v T="$duration" \
      'BEGIN {printf "%-4s | %6.2f (%5.0fx) / %5.2f               | %6.2f (%5.0fx) / %5.2f                 | %6.2f / %5.2f          | node %5.0fx, core %5.0fx; %4.2f, %4.2f\n",
              r, bw, br, bc, nw, nr, nc, cw, cc, T / bw, T / cw, bw / cw, bc / cc}'
    awk -v T="$duration" -v bc="$bag_cpu" -v nc="$nobag_cpu" -v cc="$core_cpu" \
      'BEGIN {printf "       per CPU second: node with bag %5.0fx, node without bag %5.0fx, cart_simulate %5.0fx\n", T / bc, T / nc, T / cc}'
  done
  echo "  bag: $(ls -l "$work/node.bag" | awk '{print $5}') bytes; $(rosbag info "$work/node.bag" | grep -E '^(messages|compression)' | tr -s ' ' | tr '\n' ';')"
}

# The default scene as shipped, node with its bag against cart_simulate, in turns (--default-scene-only).
# CPU time from wait4's rusage with its microseconds (the kernel's exact run time of all threads;
# /usr/bin/time prints it to 10 ms, 4 % of these runs).
precise_timed() {  # $1 output file for "wall cpu" [s]; the rest: the command
  local out="$1"; shift
  /usr/bin/python3 -c '
import os, subprocess, sys, time
start = time.monotonic()
child = subprocess.Popen(sys.argv[2:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
wall = time.monotonic() - start
open(sys.argv[1], "w").write("%.6f %.6f\n" % (wall, usage.ru_utime + usage.ru_stime))
' "$out" "$@"
}
node_pair_run() {  # $1 label -> "wall loop_rtf cpu"
  rosparam delete /cart_sim > /dev/null 2>&1 || true
  precise_timed "$work/$1.time" "$bin/cart_sim" __name:=cart_sim _scene:="$scene" _fast:=true _publish_rate:=100 \
    _duration:=$duration _summary_path:="$work/$1.summary" _bag_path:="$work/pair.bag"
  rm -f "$work/pair.bag"
  local rtf; rtf=$(grep -o 'real-time factor [0-9.e+]*' "$work/$1.summary" | awk '{print $3}'); rtf="${rtf%.}"
  awk -v rtf="$rtf" '{printf "%s %s %s", $1, rtf, $2}' "$work/$1.time"
}
core_pair_run() {  # -> "wall cpu"
  precise_timed "$work/core.time" "$bin/cart_simulate" --quiet --scene "$scene" --output-rate 100 --duration $duration \
    --output "$work/core.csv"
  cat "$work/core.time"
}
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
default_scene_pairs() {  # $1 repetitions
  echo "default scene as shipped (birkhoff_gauss4 at h = 10 ms, dopri5 shadow reference), 100 Hz, $duration s, bag on; $(nproc) cores"
  printf "%-3s | %-40s | %-26s | %-17s | %s\n" run "node: loop x (process x) / CPU ms per s" "cart_simulate: x / CPU ms per s" \
    "core/node: x, CPU" "load (1 min)"
  local values="$work/pairs.values"
  : > "$values"
  for repetition in $(seq "$1"); do
    local node_result core_result
    if ((repetition % 2)); then
      node_result="$(node_pair_run "pair_$repetition")"
      core_result="$(core_pair_run)"
    else
      core_result="$(core_pair_run)"
      node_result="$(node_pair_run "pair_$repetition")"
    fi
    read -r node_wall node_rtf node_cpu <<< "$node_result"
    read -r core_wall core_cpu <<< "$core_result"
    awk -v nw="$node_wall" -v nr="$node_rtf" -v nc="$node_cpu" -v cw="$core_wall" -v cc="$core_cpu" -v T="$duration" \
      'BEGIN {print nr, 1000 * nc / T, T / cw, 1000 * cc / T, (T / cw) / nr, cc / nc}' >> "$values"
    awk -v r="$repetition" -v nw="$node_wall" -v nr="$node_rtf" -v nc="$node_cpu" -v cw="$core_wall" -v cc="$core_cpu" \
      -v T="$duration" -v load="$(cut -d' ' -f1 /proc/loadavg)" \
      'BEGIN {printf "%-3s | %6.0fx (%5.0fx) / %6.3f                  | %6.0fx / %6.3f            | %4.2f, %4.2f        | %s\n",
              r, nr, T / nw, 1000 * nc / T, T / cw, 1000 * cc / T, (T / cw) / nr, cc / nc, load}'
  done
  local column
  for column in 1 2 3 4 5 6; do awk -v k=$column '{print $k}' "$values" | median; done | tr '\n' ' ' |
    awk '{printf "median: node loop %.0fx, %.3f CPU ms per s; cart_simulate %.0fx, %.3f CPU ms per s; core/node %.2f (x), %.2f (CPU)\n",
          $1, $2, $3, $4, $5, $6}'
}

echo "load before: $(cat /proc/loadavg)"
if ((default_scene_only)); then
  stepping=""; core_stepping=""
  default_scene_pairs "$default_scene_only"
  echo "load after:  $(cat /proc/loadavg)"
  exit 0
fi
fast_table "default scene, birkhoff2 at h = 1 ms , 100 Hz, $duration s:"
read -r none_wall none_rtf none_cpu <<< "$(node_fast "bag_none" "_bag_path:=$work/node_none.bag _bag_compression:=none")"
echo "  bag uncompressed (~bag_compression none): wall $none_wall s (loop ${none_rtf}x) / CPU $none_cpu s; $(ls -l "$work/node_none.bag" | awk '{print $5}') bytes"
stepping=""; core_stepping=""
fast_table "default scene as shipped (its own integrator and step: birkhoff_gauss4 at h = 10 ms), 100 Hz, $duration s:"
echo "load: $(cat /proc/loadavg)"

# Lockstep with the example controller: 60 s of driven.yaml at 50 Hz control.
rosparam delete /cart_sim > /dev/null 2>&1 || true
"$bin/steering_pd_controller" __name:=pd > "$work/pd.log" 2>&1 &
controller_pid=$!
timed "$work/lockstep.time" "$bin/cart_sim" __name:=cart_sim _scene:="$repo/config/scenes/driven.yaml" _fast:=true \
  _lockstep:=true _publish_rate:=50 _duration:=60 _summary_path:="$work/lockstep.summary" > "$work/lockstep.log" 2>&1 || true
kill -INT "$controller_pid" 2>/dev/null || true
wait "$controller_pid" 2>/dev/null || true
echo "lockstep (driven.yaml, 60 s at 50 Hz with steering_pd_controller): $(grep -o 'real-time factor [0-9.e+]*' "$work/lockstep.summary") of the loop; $(grep -o 'Lockstep timeouts: [0-9]*' "$work/lockstep.summary"); process wall/user/sys $(cat "$work/lockstep.time")"

# The same loop as nodelets in one manager (zero-copy messages, the controller answering inside
# cart_sim's publish), 600 s of scene time, with driven.yaml's integrator (birkhoff2 at 1 ms) and with
# birkhoff_gauss4 at 10 ms, beside the separate nodes with the same settings. The nodelet run ends
# inside the manager: its summary appears when the run is over.
nodelet_loop() {  # label, extra cart_sim arguments
  local label="$1"; shift
  rosparam delete /cart_sim > /dev/null 2>&1 || true
  /usr/lib/nodelet/nodelet manager __name:=loop_manager > "$work/manager_$label.log" 2>&1 &
  local manager_pid=$!
  /usr/lib/nodelet/nodelet load birkhoff_cart/SteeringPdController loop_manager __name:=pd > "$work/pd_$label.log" 2>&1 &
  local pd_loader=$!
  /usr/lib/nodelet/nodelet load birkhoff_cart/CartSim loop_manager __name:=cart_sim _scene:="$repo/config/scenes/driven.yaml" \
    _fast:=true _lockstep:=true _publish_rate:=50 _duration:=600 _bag_path:= _summary_path:="$work/$label.summary" "$@" \
    > "$work/$label.log" 2>&1 &
  local sim_loader=$!
  for _ in $(seq 3000); do grep -q 'Lockstep timeouts' "$work/$label.summary" 2>/dev/null && break; sleep 0.1; done
  kill -INT "$sim_loader" "$pd_loader" 2>/dev/null || true
  wait "$sim_loader" "$pd_loader" 2>/dev/null || true
  kill -INT "$manager_pid" 2>/dev/null || true
  wait "$manager_pid" 2>/dev/null || true
  echo "  nodelets in one manager: $(grep -o 'real-time factor [0-9.e+]*' "$work/$label.summary"); $(grep -o 'stepping [0-9.e+-]* s' "$work/$label.summary") of $(grep -o 'wall time [0-9.e+-]* s' "$work/$label.summary"); $(grep -o 'Lockstep timeouts: [0-9]*' "$work/$label.summary")"
}
node_loop() {  # label, extra cart_sim arguments
  local label="$1"; shift
  rosparam delete /cart_sim > /dev/null 2>&1 || true
  "$bin/steering_pd_controller" __name:=pd > "$work/pd_$label.log" 2>&1 &
  local controller_pid=$!
  "$bin/cart_sim" __name:=cart_sim _scene:="$repo/config/scenes/driven.yaml" _fast:=true _lockstep:=true _publish_rate:=50 \
    _duration:=600 _bag_path:= _summary_path:="$work/$label.summary" "$@" > "$work/$label.log" 2>&1 || true
  kill -INT "$controller_pid" 2>/dev/null || true
  wait "$controller_pid" 2>/dev/null || true
  echo "  two node processes:      $(grep -o 'real-time factor [0-9.e+]*' "$work/$label.summary"); $(grep -o 'stepping [0-9.e+-]* s' "$work/$label.summary") of $(grep -o 'wall time [0-9.e+-]* s' "$work/$label.summary"); $(grep -o 'Lockstep timeouts: [0-9]*' "$work/$label.summary")"
}
# Wall-clock ROS time: a lockstep loop needs no /clock listener (stamps are scene time), and under
# /use_sim_time the nodelet manager would hear every /clock cart_sim publishes (roscpp's own
# subscription, which the cart_sim executable remaps away).
rosparam set /use_sim_time false
echo "lockstep loop, driven.yaml, 600 s at 50 Hz, no bag, /use_sim_time false, birkhoff2 at h = 1 ms (the scene's):"
node_loop loop_nodes_b2
nodelet_loop loop_nodelets_b2
echo "lockstep loop, driven.yaml, 600 s at 50 Hz, no bag, /use_sim_time false, birkhoff_gauss4 at h = 10 ms:"
node_loop loop_nodes_g4 _integrator:=birkhoff_gauss4 _step_size:=0.01
nodelet_loop loop_nodelets_g4 _integrator:=birkhoff_gauss4 _step_size:=0.01
rosparam set /use_sim_time true

# Real time at 1 kHz: CPU share of one core over 15 s after a 3 s start-up.
rosparam delete /cart_sim > /dev/null 2>&1 || true
"$bin/cart_sim" __name:=cart_sim _scene:="$scene" _integrator:=birkhoff2 _step_size:=0.001 _fast:=false _publish_rate:=100 _duration:=25 \
  > "$work/real_time.log" 2>&1 &
node_pid=$!
sleep 3
ticks0=$(cpu_ticks "$node_pid"); ns0=$(cpu_nanoseconds "$node_pid"); wall0=$(date +%s.%N)
switches0=$(awk '/^voluntary_ctxt_switches/ {print $2}' "/proc/$node_pid/status")
sleep 15
ticks1=$(cpu_ticks "$node_pid"); ns1=$(cpu_nanoseconds "$node_pid"); wall1=$(date +%s.%N)
switches1=$(awk '/^voluntary_ctxt_switches/ {print $2}' "/proc/$node_pid/status")
wait "$node_pid" || true
awk -v t0="$ticks0" -v t1="$ticks1" -v w0="$wall0" -v w1="$wall1" -v hz="$clock_ticks" \
  'BEGIN {printf "real-time mode, default scene, h = 1 ms, 100 Hz publishing: CPU %.2f s over %.2f s wall = %.2f%% of one core (clock ticks)\n", (t1 - t0) / hz, w1 - w0, 100 * (t1 - t0) / hz / (w1 - w0)}'
awk -v n0="$ns0" -v n1="$ns1" -v w0="$wall0" -v w1="$wall1" -v s0="$switches0" -v s1="$switches1" \
  'BEGIN {printf "  the same window by schedstat (all threads, ns): CPU %.4f s = %.2f%% of one core; main thread %.0f wake-ups per second\n", (n1 - n0) / 1e9, 100 * (n1 - n0) / 1e9 / (w1 - w0), (s1 - s0) / (w1 - w0)}'
# Command latency in real-time mode: a responder answers every /clock (published at each 100 Hz
# publish instant t_k) with a steering_torque at once; the node records each command at the scene
# time of the step it takes effect after, t_c. t_c - t_k (scene time = wall time at factor 1) is
# the round trip: transport both ways + the node's wake-up, rounded down to a step.
rosparam delete /cart_sim > /dev/null 2>&1 || true
cat > "$work/responder.py" <<'PY'
import rospy
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64
rospy.init_node("latency_responder")
publisher = rospy.Publisher("steering_torque", Float64, queue_size=100, tcp_nodelay=True)
rospy.Subscriber("/clock", Clock, lambda clock: publisher.publish(Float64(0.5)), queue_size=100, tcp_nodelay=True)
rospy.spin()
PY
/usr/bin/python3 "$work/responder.py" > "$work/responder.log" 2>&1 &
responder_pid=$!
sleep 2
"$bin/cart_sim" __name:=cart_sim _scene:="$repo/config/scenes/driven.yaml" _fast:=false _publish_rate:=100 _duration:=10 \
  _bag_path:="$work/latency.bag" > "$work/latency.log" 2>&1 || true
kill -INT "$responder_pid" 2>/dev/null || true
wait "$responder_pid" 2>/dev/null || true
/usr/bin/python3 - "$work/latency.bag" <<'PY'
import sys, math, rosbag
stamps = [m.timestamp.to_sec() for m in rosbag.Bag(sys.argv[1]).read_messages(topics=["/steering_torque"])]
latencies = sorted(t - math.floor(t * 100 + 1e-9) / 100 for t in stamps)
n = len(latencies)
if n:
    print("real-time command latency (answer to each /clock, 10 s, %d commands): median %.1f ms, 90%% %.1f ms, max %.1f ms of scene time (h = 1 ms)"
          % (n, 1e3 * latencies[n // 2], 1e3 * latencies[int(0.9 * n)], 1e3 * latencies[-1]))
else:
    print("real-time command latency: no command recorded")
PY
echo "load after:  $(cat /proc/loadavg)"

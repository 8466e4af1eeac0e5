#!/usr/bin/env bash
# Records the same deterministic cart_sim runs with two builds of the package and compares their
# bags byte for byte: a refactoring of the node (or of the core under it) must leave them equal.
#
#   bash checks/bag_identity.sh BEFORE_WORKSPACE AFTER_WORKSPACE
#   (each a catkin workspace holding a build of birkhoff_cart, e.g. a clone's .ws at an earlier commit)
#
# Runs (~record_wall_time false, so a bag does not depend on the machine): the default scene (shadow
# reference), the noisy odometry sensor, the steering actuator with end stops, the paper's special
# case (its end is off the step grid), a ~duration that ends off the grid, a run paused, advanced by
# ~step and teleported by ~set_state, and the lockstep closed loop with steering_pd_controller.
# Prints one line per run and "N equal, N differ"; exits non-zero when any bag differs or a run fails.
set -uo pipefail
export PATH="/usr/bin:/bin:$PATH"
if [ $# -ne 2 ]; then
  echo "usage: bash checks/bag_identity.sh BEFORE_WORKSPACE AFTER_WORKSPACE" >&2
  exit 2
fi
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scenes="$repo/config/scenes"
out="$(mktemp -d /tmp/bag_identity.XXXXXX)"
port=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$port" ROS_HOME="$out/ros_home"
mkdir -p "$ROS_HOME"

# name|private parameters of cart_sim (the scene and the bag are added)
runs=(
  "default|_scene:=$scenes/default.yaml _duration:=30.0"
  "noisy_odometry|_scene:=$scenes/noisy_odometry.yaml _duration:=20.0"
  "steering_actuator|_scene:=$scenes/steering_actuator.yaml _duration:=10.0"
  "paper_special|_scene:=$scenes/paper_special.yaml"
  "off_grid_end|_scene:=$scenes/default.yaml _duration:=7.0005 _publish_rate:=30.0"
)

run_cart_sim() {  # workspace name parameters...
  local workspace="$1" name="$2"
  shift 2
  (
    set +u
    # shellcheck disable=SC1091
    source "$workspace/devel/setup.bash"
    rosparam delete /cart_sim >/dev/null 2>&1
    timeout 300 "$workspace/devel/lib/birkhoff_cart/cart_sim" "$@" _fast:=true _record_wall_time:=false \
      _publish_clock:=true _bag_path:="$out/$name.bag" >"$out/$name.log" 2>&1
  )
}

run_stepped() {  # workspace name: paused at the start, ~step 250 (2.5 s), a ~set_state teleport (the rest of
  # the run replanned from there), ~step 37, then ~pause false to the end
  local workspace="$1" name="$2"
  (
    set +u
    # shellcheck disable=SC1091
    source "$workspace/devel/setup.bash"
    rosparam delete /cart_sim >/dev/null 2>&1
    timeout 300 "$workspace/devel/lib/birkhoff_cart/cart_sim" _scene:="$scenes/default.yaml" _duration:=6.0 \
      _fast:=true _record_wall_time:=false _start_paused:=true _bag_path:="$out/$name.bag" >"$out/$name.log" 2>&1 &
    local node=$!
    timeout 30 rosservice call --wait /cart_sim/step "steps: 250" >/dev/null &&
      timeout 30 rosservice call /cart_sim/set_state \
        "{x: 1.0, y: -2.0, heading: 0.5, steering_angle: 0.2, forward_speed: 1.5, steering_rate: 0.1}" >/dev/null &&
      timeout 30 rosservice call /cart_sim/step "steps: 37" >/dev/null &&
      timeout 30 rosservice call /cart_sim/pause "data: false" >/dev/null
    wait "$node"
  )
}

run_lockstep() {  # workspace name
  local workspace="$1" name="$2"
  (
    set +u
    # shellcheck disable=SC1091
    source "$workspace/devel/setup.bash"
    timeout 300 roslaunch birkhoff_cart lockstep.launch nodelets:=false duration:=30 \
      bag_path:="$out/$name.bag" >"$out/$name.log" 2>&1
  )
}

roscore -p "$port" >"$out/roscore.log" 2>&1 &
roscore_pid=$!
trap 'kill $roscore_pid 2>/dev/null; wait $roscore_pid 2>/dev/null' EXIT
for _ in $(seq 100); do
  rosparam list >/dev/null 2>&1 && break
  sleep 0.1
done

equal=0
differ=0
compare() {  # name status_before status_after
  local name="$1"
  if [ "$2" -ne 0 ] || [ "$3" -ne 0 ] || [ ! -s "$out/before_$name.bag" ] || [ ! -s "$out/after_$name.bag" ]; then
    echo "FAILED  $name (exit $2 before, $3 after; logs in $out)"
    differ=$((differ + 1))
  elif cmp -s "$out/before_$name.bag" "$out/after_$name.bag"; then
    echo "equal   $name ($(stat -c %s "$out/after_$name.bag") bytes, md5 $(md5sum <"$out/after_$name.bag" | cut -c1-12))"
    equal=$((equal + 1))
  else
    echo "DIFFER  $name (bags in $out)"
    differ=$((differ + 1))
  fi
}

for entry in "${runs[@]}"; do
  name="${entry%%|*}"
  # shellcheck disable=SC2086
  run_cart_sim "$1" "before_$name" ${entry#*|}
  before=$?
  # shellcheck disable=SC2086
  run_cart_sim "$2" "after_$name" ${entry#*|}
  compare "$name" "$before" $?
done
run_stepped "$1" before_stepped
before=$?
run_stepped "$2" after_stepped
compare stepped "$before" $?
kill "$roscore_pid" 2>/dev/null
wait "$roscore_pid" 2>/dev/null
trap - EXIT
# roslaunch starts its own master on this port once the roscore is gone.
run_lockstep "$1" before_lockstep
before=$?
run_lockstep "$2" after_lockstep
compare lockstep "$before" $?

echo "$equal equal, $differ differ"
[ "$differ" -eq 0 ]

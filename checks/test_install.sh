#!/usr/bin/env bash
# The install space works: installs the built workspace into a temporary prefix (never .ws/install)
# and runs the package from there with nothing of the source tree or devel space in the
# environment:
#   1. cart_simulate --version, and a 1 s run of the installed free_coast scene (exit 0, 101 rows),
#      without sourcing anything (the executables find the package's libraries by their RPATH);
#   2. with only <prefix>/setup.bash sourced: rospack finds the package in the prefix, the Python
#      module birkhoff_cart.simulator imports from the prefix and runs 1 s of the installed free_coast
#      scene on the prefix's core library, and `roslaunch birkhoff_cart sim.launch` runs 2 s of scene
#      time (fast, recorded) on a private master and cart_sim ends with "finished".
# About 30 s on a built workspace. Prints "N passed, N failed" and exits non-zero on a failure.
#
# Usage: checks/test_install.sh [--no-build]
#   BIRKHOFF_CART_WORKSPACE=/path/to/ws: use that built workspace instead of setting up .ws/;
#   --no-build: install what is built, without `cmake --build` first (the gtest install_space_test
#   runs it so, from inside `catkin_make run_tests`).
set -uo pipefail
build=true
if [ "${1:-}" = "--no-build" ]; then build=false; fi
# shellcheck source=scripts/workspace.sh
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/workspace.sh"  # → $repo, $workspace (set up and built)

# DESTDIR install: catkin writes the workspace files (setup.bash, .catkin, ...) to the configured
# CMAKE_INSTALL_PREFIX, so the whole tree goes under a temporary DESTDIR instead; every catkin
# setup file finds its workspace from its own location, so the moved tree is a real install space.
destdir="$(mktemp -d /tmp/birkhoff_cart_install.XXXXXX)"
trap 'rm -rf "$destdir"' EXIT
configured_prefix="$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$workspace/build/CMakeCache.txt")"
prefix="$destdir$configured_prefix"
passed=0
failed=0
check() {  # check NAME COMMAND...: runs COMMAND, counts and reports it
  local name="$1"
  shift
  if "$@" > "$destdir/check.log" 2>&1; then
    echo "test_install: ok   $name"
    passed=$((passed + 1))
  else
    echo "test_install: FAIL $name"
    sed 's/^/    /' "$destdir/check.log" | tail -n 30
    failed=$((failed + 1))
  fi
}

echo "== build and install $workspace into $prefix"
touch "$destdir/build.log"
if { $build && ! cmake --build "$workspace/build" -- -j2 > "$destdir/build.log" 2>&1; } ||
  ! DESTDIR="$destdir" cmake --install "$workspace/build" > "$destdir/install.log" 2>&1; then
  tail -n 30 "$destdir/build.log" "$destdir/install.log"
  echo "0 passed, 1 failed"
  exit 1
fi

# A clean environment: Debian's ROS in /usr, nothing of the workspace or the source tree.
clean_env=(env -i "HOME=$destdir/home" "PATH=/usr/bin:/bin" "LANG=C.UTF-8" "ROS_HOME=$destdir/ros_home")
mkdir -p "$destdir/home" "$destdir/ros_home"
bin="$prefix/lib/birkhoff_cart"

check "cart_simulate --version (unsourced)" "${clean_env[@]}" "$bin/cart_simulate" --version
check "cart_simulate loads libbirkhoff_cart_core.so from the prefix" "${clean_env[@]}" bash -c '
  library="$(ldd "$1/cart_simulate" | sed -n "s/^.*libbirkhoff_cart_core.so => \(.*\) (0x.*$/\1/p")" &&
  test "$(readlink -f "$library")" = "$2/lib/libbirkhoff_cart_core.so"' _ "$bin" "$prefix"
check "cart_simulate runs the installed free_coast scene (unsourced)" "${clean_env[@]}" bash -c '
  "$1/cart_simulate" --scene "$2/share/birkhoff_cart/config/scenes/free_coast.yaml" --duration 1 \
    --output "$3/free_coast.csv" && test "$(wc -l < "$3/free_coast.csv")" -eq 102' _ "$bin" "$prefix" "$destdir"
check "cart_sim --version (unsourced)" "${clean_env[@]}" "$bin/cart_sim" --version
check "rospack finds the package in the prefix" "${clean_env[@]}" bash -c '
  source "$1/setup.bash" && test "$(rospack find birkhoff_cart)" = "$1/share/birkhoff_cart"' _ "$prefix"
check "installed message type birkhoff_cart/IntegrationError" "${clean_env[@]}" bash -c '
  source "$1/setup.bash" && rosmsg show birkhoff_cart/IntegrationError | grep -q .' _ "$prefix"

check "the Python module runs the installed free_coast scene (prefix sourced), on the prefix's core" "${clean_env[@]}" bash -c '
  source "$1/setup.bash" && cd "$2" && /usr/bin/python3 -c "
import os, sys
from birkhoff_cart import simulator
assert simulator.__file__.startswith(sys.argv[1]), simulator.__file__
scene = simulator.load_scene(os.path.join(sys.argv[1], \"share/birkhoff_cart/config/scenes/free_coast.yaml\"), {\"duration\": 1.0})
assert simulator.Simulation(scene).run()[0] == 1.0
maps = open(\"/proc/self/maps\").read()
assert os.path.join(sys.argv[1], \"lib/libbirkhoff_cart_core.so\") in maps, \"core not from the prefix\"
" "$1"' _ "$prefix" "$destdir"
port="$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')"
check "roslaunch birkhoff_cart sim.launch, 2 s of scene time, from the prefix" "${clean_env[@]}" bash -c '
  source "$1/setup.bash" && export ROS_MASTER_URI="http://localhost:$2" &&
  timeout 120 roslaunch -p "$2" birkhoff_cart sim.launch fast:=true record:=true duration:=2 \
    bag_path:="$3/sim.bag" summary_path:="$3/summary.txt" < /dev/null &&
  grep "^cart_sim summary: finished" "$3/summary.txt" && test -s "$3/sim.bag"' _ "$prefix" "$port" "$destdir"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]

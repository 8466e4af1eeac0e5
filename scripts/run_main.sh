#!/usr/bin/env bash
# The main job (README.md, "The two commands"): set up and build, then run the ROS simulator headless in fast mode on the
# default scene for 60 s of simulated time, recording a compressed bag, and print the bag's
# `rosbag info`, the node's one-paragraph summary and a picture of the run drawn from the bag
# (plot_bag: path, steering angle, speed, error diagnostics). Needs no display and no stdin;
# roslaunch starts its own master on a free port and exits when cart_sim (required) finishes.
#
# Usage: scripts/run_main.sh   → output/main.bag, output/main_summary.txt, output/main.png
# Developers with their own built workspace: BIRKHOFF_CART_WORKSPACE=/path/to/ws skips set-up and
# uses that workspace instead of .ws/.
set -euo pipefail
# shellcheck source=scripts/workspace.sh
source "$(dirname "${BASH_SOURCE[0]}")/workspace.sh"  # → $repo, $workspace (set up and built)

set +u  # catkin's setup files read unset variables
# shellcheck disable=SC1091
source "$workspace/devel/setup.bash"
set -u

output="$repo/output"
mkdir -p "$output"
bag="$output/main.bag"
summary="$output/main_summary.txt"
picture="$output/main.png"
rm -f "$bag" "$bag.active" "$summary" "$picture"

# A private master on a free port, so a roscore already running elsewhere is left alone.
port="$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://localhost:$port"
export ROS_HOME="${ROS_HOME:-$output/ros_home}"

echo "== roslaunch birkhoff_cart sim.launch (fast, recorded, 60 s of simulated time; master on port $port)"
timeout 1800 roslaunch -p "$port" birkhoff_cart sim.launch fast:=true record:=true rviz:=false duration:=60 \
  bag_path:="$bag" summary_path:="$summary" < /dev/null

echo
echo "== rosbag info $bag"
if [ ! -f "$bag" ]; then
  echo "run_main: no bag at $bag (cart_sim did not finish its record)" >&2
  exit 1
fi
rosbag info "$bag"

echo
echo "== rosrun birkhoff_cart plot_bag $bag"
rosrun birkhoff_cart plot_bag "$bag" -o "$picture"

echo
echo "== cart_sim summary"
if [ ! -f "$summary" ]; then
  echo "run_main: cart_sim wrote no summary to $summary" >&2
  exit 1
fi
cat "$summary"
if ! grep -q "^cart_sim summary: finished" "$summary"; then
  echo "run_main: the simulation did not finish cleanly" >&2
  exit 1
fi

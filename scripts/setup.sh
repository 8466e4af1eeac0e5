#!/usr/bin/env bash
# Set-up for birkhoff_cart on Debian bookworm, as root: install the Debian packages the project
# needs (only those missing), make the catkin workspace .ws/ (its package directory links to this
# repository's files) and build it. Idempotent: with nothing changed a second run takes seconds.
#
# Usage: scripts/setup.sh            (then: source .ws/devel/setup.bash)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Debian's python3 (with the ROS modules) must win over the pyenv interpreter on PATH: catkin,
# ament's CMake helpers, rostest and roslaunch all call `python3`.
export PATH="/usr/bin:/bin:$PATH"

# Every Debian package the build, the tests, the main job and the plots use.
packages=(
  build-essential cmake
  catkin ros-core-dev ros-message-generation ros-message-runtime
  libroscpp-dev librosbag-dev libtf2-ros-dev libtf2-geometry-msgs-dev
  libstd-msgs-dev libstd-srvs-dev ros-std-srvs python3-std-srvs
  libnav-msgs-dev libsensor-msgs-dev libgeometry-msgs-dev
  libdiagnostic-updater-dev libdiagnostic-msgs-dev
  python3-rostest python3-rosbag python3-rostopic python3-roslaunch python3-rosnode
  python3-rosservice python3-roswtf python3-tf2-ros python3-rosgraph-msgs python3-catkin-pkg python3-empy
  # the message classes `rostopic echo` needs for odom, joint_states, /diagnostics, /tf, cmd_vel
  python3-std-msgs python3-geometry-msgs python3-nav-msgs python3-sensor-msgs python3-diagnostic-msgs
  python3-tf2-msgs
  rosbash ros-robot-state-publisher liburdf-dev rviz xvfb
  # the tf command-line tools beside the simulator: `rosrun tf tf_echo odom base_link`,
  # `rosrun tf2_tools echo.py`, `rosrun tf2_tools view_frames.py` (tf_tools.test)
  tf-tools libtf-dev tf2-tools
  # the nodelets (nodelet_plugins.xml) and `rosrun nodelet nodelet manager`
  libnodeletlib-dev libnodelet-dev libnodeletlib-tools pluginlib-dev
  # cmd_vel_controller's run-time settings (cfg/CmdVelController.cfg; `rosrun dynamic_reconfigure dynparam`)
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libboost-dev libyaml-cpp-dev libeigen3-dev googletest libgtest-dev
  # the right-hand sides' sin, cos, tanh, exp, pow with the same bits on every CPU (deterministic_math.h)
  libsleef-dev
  python3-matplotlib python3-numpy
  # the study runner (scripts/study): Dask distributed, its local cluster and the row tables
  python3-distributed python3-dask python3-pandas python3-yaml
  # the Python module birkhoff_cart.simulator (docs/python.md) and its tests
  pybind11-dev python3-pybind11 python3-numpy python3-pytest
  # its study-file schema (python3-jsonschema) and its unit tests (python3-pytest: scripts/run_tests.sh)
  python3-jsonschema
)
missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} missing Debian package(s): ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The workspace's package directory .ws/src/birkhoff_cart is a real directory of links to the
# repository's top-level entries, all but .ws itself (and git's and the outputs' directories).
# ROS_PACKAGE_PATH (= .ws/src) then never leads back into .ws: a link to the whole repository made
# rosrun's `find -L` report "File system loop detected" and find every executable twice.
workspace="$repo/.ws"
package_dir="$workspace/src/birkhoff_cart"
mkdir -p "$workspace/src"
if [ -L "$package_dir" ]; then rm -f "$package_dir"; fi  # the earlier layout: a link to the repository
mkdir -p "$package_dir"
shopt -s dotglob nullglob
for entry in "$package_dir"/*; do  # links whose target left the repository
  if [ -L "$entry" ] && [ ! -e "$entry" ]; then rm -f "$entry"; fi
done
for entry in "$repo"/*; do
  name="$(basename "$entry")"
  case "$name" in .ws | .ws_* | .git | output | build | devel | install) continue ;; esac
  if [ "$(readlink "$package_dir/$name" 2>/dev/null)" != "$entry" ]; then ln -sfn "$entry" "$package_dir/$name"; fi
done
shopt -u dotglob nullglob

# catkin's generated setup files read unset variables; keep `set -u` out of them.
set +u
cd "$workspace"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_BUILD_TYPE=Release -j2 "$@"

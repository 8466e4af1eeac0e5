#!/usr/bin/env bash
# Set-up for birkhoff_cart on Debian bookworm, as root: install the Debian packages the project
# needs (only those missing), make the catkin workspace .ws/ (its src/ links to this repository)
# and build it. Idempotent: with nothing changed a second run takes seconds.
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
  python3-rosservice python3-tf2-ros python3-rosgraph-msgs python3-catkin-pkg python3-empy
  rosbash ros-robot-state-publisher liburdf-dev rviz xvfb
  libboost-dev libyaml-cpp-dev libeigen3-dev googletest libgtest-dev
  python3-matplotlib python3-numpy
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

workspace="$repo/.ws"
mkdir -p "$workspace/src"
if [ ! -L "$workspace/src/birkhoff_cart" ]; then
  ln -sfn "$repo" "$workspace/src/birkhoff_cart"
fi

# catkin's generated setup files read unset variables; keep `set -u` out of them.
set +u
cd "$workspace"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_BUILD_TYPE=Release -j2 "$@"

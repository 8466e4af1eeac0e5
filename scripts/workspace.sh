# Sourced by the run_* scripts: the repository path, Debian's python3 first on PATH, and the
# catkin workspace to use — $BIRKHOFF_CART_WORKSPACE when a developer already built one, otherwise
# .ws/ made (or brought up to date) by scripts/setup.sh.
# After sourcing: $repo, $workspace.
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Debian's python3 (with the ROS modules) must win over the pyenv interpreter on PATH.
export PATH="/usr/bin:/bin:$PATH"
workspace="${BIRKHOFF_CART_WORKSPACE:-}"
if [ -z "$workspace" ]; then
  "$repo/scripts/setup.sh"
  workspace="$repo/.ws"
fi

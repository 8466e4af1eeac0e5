#!/usr/bin/env bash
# Set up, build, run every gtest and rostest of birkhoff_cart, and print one closing line
# "N passed, N failed" (gtest and rostest cases together). Exits non-zero when anything failed, was
# skipped or did not run: test/expected_results.txt lists every result file and its minimum number
# of cases (checks/count_test_results.py). `catkin_make run_tests` exits 0 on failures, so the result XML decides.
set -uo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Debian's python3 (with the ROS modules) must win over the pyenv interpreter on PATH: catkin,
# ament's CMake helpers, rostest and roslaunch all call `python3`.
export PATH="/usr/bin:/bin:$PATH"
workspace="$repo/.ws"

if ! "$repo/scripts/setup.sh"; then
  echo "build failed"
  echo "0 passed, 1 failed"
  exit 1
fi

results="$workspace/build/test_results/birkhoff_cart"
rm -rf "$results"
set +u
# shellcheck disable=SC1091
source "$workspace/devel/setup.bash"
cd "$workspace"
# Build the test executables on both cores, then run the tests one at a time: several of them are
# real-time (the 10 kHz command flood, the wall-clock pace of the node, rviz under Xvfb) and must
# not share the two cores with the long-horizon integrations.
catkin_make tests -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 -j2 &&
  catkin_make run_tests -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 -j1
run_status=$?
set -u

echo
echo "== catkin_test_results"
catkin_test_results --verbose "$workspace/build/test_results" | tail -n 40
results_status=${PIPESTATUS[0]}

/usr/bin/python3 "$repo/checks/count_test_results.py" "$results" \
  --manifest "$repo/test/expected_results.txt" --sources "$repo"
count_status=$?

if [ "$run_status" -ne 0 ] || [ "$results_status" -ne 0 ] || [ "$count_status" -ne 0 ]; then
  exit 1
fi
exit 0

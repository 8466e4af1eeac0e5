#!/usr/bin/env bash
# Set up, build, run every gtest and rostest of birkhoff_cart, then the ROS-free unit tests under
# ASan+UBSan and two mutations of the kill list, and print one closing line "N passed, N failed"
# (gtest and rostest cases, sanitized runs and mutations together). Exits non-zero when anything failed, was
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

# The ROS-free unit tests (core, integrators, scenes, the CLI) and cart_simulate on every shipped
# scene once more under AddressSanitizer + UndefinedBehaviorSanitizer (-fno-sanitize-recover), in a
# workspace of their own (.ws_sanitize_gcc); each run is one case of sanitize-ros_free.xml, which
# the count below includes. The full pass (ROS-layer unit tests too) is checks/sanitize.sh.
echo
echo "== sanitizers (checks/sanitize.sh --ros-free)"
bash "$repo/checks/sanitize.sh" --ros-free --junit "$results/sanitize-ros_free.xml"
sanitize_status=$?

# Two mutations of checks/mutation_check.py's kill list, chosen by the commit's hash (a different
# pair per commit), applied to a scratch copy (.ws_mutation) and each killed by its tests; every
# run also checks that each mutation's target still exists (mutation_targets_test). The whole list:
# /usr/bin/python3 checks/mutation_check.py.
echo
echo "== mutations (checks/mutation_check.py --rotate 2)"
/usr/bin/python3 "$repo/checks/mutation_check.py" --rotate 2 --scratch "$repo/.ws_mutation" \
  --junit "$results/mutation-rotation.xml"
mutation_status=$?

echo
echo "== catkin_test_results"
catkin_test_results --verbose "$workspace/build/test_results" | tail -n 40
results_status=${PIPESTATUS[0]}

/usr/bin/python3 "$repo/checks/count_test_results.py" "$results" \
  --manifest "$repo/test/expected_results.txt" --sources "$repo"
count_status=$?

if [ "$run_status" -ne 0 ] || [ "$results_status" -ne 0 ] || [ "$count_status" -ne 0 ] ||
  [ "$sanitize_status" -ne 0 ] || [ "$mutation_status" -ne 0 ]; then
  exit 1
fi
exit 0

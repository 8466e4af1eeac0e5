#!/usr/bin/env bash
# Sanitizers as a habit: builds the core, the CLI, the unit tests and the ROS-layer unit tests with
# AddressSanitizer + UndefinedBehaviorSanitizer + float-cast-overflow (GCC has it but leaves it out
# of -fsanitize=undefined; clang includes it: named explicitly for both) in a workspace of its own
# (.ws_sanitize_<compiler>/, never .ws/), runs every one of those tests and cart_simulate on every
# shipped scene (config/scenes/*.yaml, full duration), and fails on any report: the first UBSan
# report aborts the process (-fno-sanitize-recover=all), ASan aborts on its first error, LSan
# fails the process at exit; ASan and LSan write every process's report to a file (log_path), so a
# report of a child (cart_simulate under cli_test) counts even though its parent captures its
# stderr; the logs are also searched for a report. Every run first proves that on small programs
# with one defect each (--self-check).
#
# No suppressions: every leak report fails the run.
# bad_input_test's memory-growth check runs with a 1 MiB ASan quarantine (quarantine_size_mb=1):
# with the default 256 MiB quarantine every freed block stays resident and the flood would look
# like growth.
#
# Usage: checks/sanitize.sh [--compiler gcc|clang] [--no-build] [--self-check] [--ros-free]
#                           [--jobs N] [--junit FILE]
#        (default gcc, the project's compiler; with clang the build stops at clang-only warnings,
#        since the package builds with -Werror; --self-check only proves the report detection, 3 s;
#        --ros-free builds and runs only the ROS-free unit tests (test/unit: core, integrators,
#        scenes, the CLI) but the two long-horizon ones, and cart_simulate on the shipped scenes:
#        the step scripts/run_tests.sh runs; --jobs runs N tests at once (default 2, the cores of
#        the CI machine); --junit writes every run as a test case of a JUnit XML file, which the
#        test count of scripts/run_tests.sh includes)
# Prints "N passed, N failed" and the wall time of the build and of the runs and the CPU time;
# exits non-zero on any failure or report.
set -uo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="/usr/bin:/bin:$PATH"
compiler=gcc
build=true
self_check_only=false
ros_free=false
parallel=2
junit=""
while [ $# -gt 0 ]; do
  case "$1" in
    --compiler) compiler="${2:-}"; shift 2 ;;
    --no-build) build=false; shift ;;  # run what the last build left (a missing test fails)
    --self-check) self_check_only=true; build=false; shift ;;  # only prove that reports are caught
    --ros-free) ros_free=true; shift ;;  # test/unit and the CLI only: no roscpp, no rosbag
    --jobs) parallel="${2:-}"; [[ "$parallel" =~ ^[1-9][0-9]*$ ]] || { echo "sanitize: --jobs needs a positive count" >&2; exit 2; }; shift 2 ;;
    --junit) junit="${2:-}"; [ -n "$junit" ] || { echo "sanitize: --junit needs a file name" >&2; exit 2; }; shift 2 ;;
    *) echo "sanitize: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
case "$compiler" in
  clang) cc=clang cxx=clang++ ;;
  gcc) cc=gcc cxx=g++ ;;
  *) echo "sanitize: --compiler must be gcc or clang, got '$compiler'" >&2; exit 2 ;;
esac

workspace="$repo/.ws_sanitize_$compiler"
mkdir -p "$workspace/src"
[ -L "$workspace/src/birkhoff_cart" ] || ln -sfn "$repo" "$workspace/src/birkhoff_cart"
# -Wno-maybe-uninitialized: with -fsanitize=address GCC 12 reports false "may be used
# uninitialized" inside libstdc++'s std::regex / std::function, and the package builds with -Werror.
flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer -g1 -O1"
[ "$compiler" = gcc ] && flags="$flags -Wno-maybe-uninitialized"

unit_tests=()
sources=("$repo"/test/unit/*_test.cpp)
$ros_free || sources+=("$repo"/test/ros_unit/*_test.cpp)
# The longest runs first, so that the parallel runs end together.
longest_first=(long_horizon_test long_run_test random_hard_cases_test hard_cases_test independent_model_test)
# install_space_test installs a fully built workspace (cart_sim too): not a memory check. The
# --ros-free step leaves out the two long-horizon tests: they run the integrators' code paths that
# the contract, collocation and hard-case tests run, for 10^4–10^5 steps more (about 400 s under
# ASan on the 2-core machine); the full pass runs them.
left_out=(install_space_test)
$ros_free && left_out+=(long_horizon_test long_run_test)
for test in "${longest_first[@]}" $(for source in "${sources[@]}"; do basename "$source" .cpp; done); do
  [[ " ${left_out[*]} ${unit_tests[*]} " == *" $test "* ]] && continue
  [ -f "$repo/test/unit/$test.cpp" ] || [ -f "$repo/test/ros_unit/$test.cpp" ] || continue
  [ -f "$repo/test/ros_unit/$test.cpp" ] && $ros_free && continue
  unit_tests+=("$test")
done

$build && echo "== build ($compiler: $flags) in $workspace"
# Configure with catkin_make (and build the core), then make the wanted targets through CMake's Makefile2:
# the top-level Makefile builds its goals one after another, Makefile2 builds them in parallel.
targets=()
for target in birkhoff_cart_core cart_simulate "${unit_tests[@]}"; do
  targets+=("birkhoff_cart/CMakeFiles/$target.dir/all")
done
set +u
build_status=0
build_start=$SECONDS
if $build; then (
  cd "$workspace" &&
    catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=None \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
      -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -j2 --make-args birkhoff_cart_core &&
    make -C build -f CMakeFiles/Makefile2 -j2 "${targets[@]}"
) > "$workspace/build.log" 2>&1 || build_status=$?; fi
set -u
build_seconds=$((SECONDS - build_start))
junit_cases=()  # "<name> <seconds> <ok|FAIL> <log>" per run, for --junit
write_junit() {  # one JUnit XML file, a test case per run, the failure text from its log
  [ -n "$junit" ] || return 0
  mkdir -p "$(dirname "$junit")"
  /usr/bin/python3 - "$junit" "${junit_cases[@]}" <<'JUNIT'
import sys
from xml.sax.saxutils import escape, quoteattr
path, cases = sys.argv[1], [c.split(" ", 3) for c in sys.argv[2:]]
failures = sum(1 for c in cases if c[2] != "ok")
lines = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<testsuite name="sanitize" tests="{len(cases)}" failures="{failures}" errors="0">']
for name, seconds, verdict, log in cases:
    lines.append(f'  <testcase classname="sanitize" name={quoteattr(name)} time="{seconds}">')
    if verdict != "ok":
        try:
            text = open(log, errors="replace").read()[-4000:]
        except OSError:
            text = "no log"
        lines.append(f'    <failure message={quoteattr("sanitizer report or failure: " + log)}>{escape(text)}</failure>')
    lines.append("  </testcase>")
lines.append("</testsuite>")
open(path, "w").write("\n".join(lines) + "\n")
JUNIT
}

if [ "$build_status" -ne 0 ]; then
  grep -E "error|Error" "$workspace/build.log" | head -n 30
  echo "sanitize: build failed (log: $workspace/build.log)"
  junit_cases+=("build 0 FAIL $workspace/build.log")
  write_junit
  echo "0 passed, 1 failed"
  exit 1
fi

runs_start=$SECONDS
bin="$workspace/devel/lib/birkhoff_cart"
# The binaries find libbirkhoff_cart_core.so through RUNPATH, which LD_LIBRARY_PATH overrides: a
# caller that sourced another workspace's devel/setup.bash (scripts/run_tests.sh does) would have
# them load that uninstrumented library. This workspace's library comes first, and is checked
# (on ldd's whole output: piped into `grep -q`, which exits at the match, ldd could die of SIGPIPE
# and pipefail would count the pipeline failed).
export LD_LIBRARY_PATH="$workspace/devel/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
if $self_check_only; then :; elif ! grep -q "libbirkhoff_cart_core.so => $workspace/devel/lib/" <<<"$(ldd "$bin/cart_simulate")"; then
  echo "sanitize: cart_simulate does not load the sanitized libbirkhoff_cart_core.so of $workspace:" >&2
  ldd "$bin/cart_simulate" | grep birkhoff >&2
  echo "0 passed, 1 failed"
  exit 1
fi
logs="$workspace/logs"
reports="$logs/reports"  # every sanitizer report of every process, children included
rm -rf "$logs"
mkdir -p "$reports"
common="abort_on_error=0:halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
unset LSAN_OPTIONS  # no suppressions
passed=0
failed=0
run() {  # run NAME TIMEOUT ASAN_EXTRA COMMAND...: one sanitized run, judged by exit status and reports
  local name="$1" limit="$2" extra="$3"
  shift 3
  local log="$logs/$name.log"
  local start=$SECONDS
  # log_path: each process writes its reports to $reports/$name.<pid>, also a child whose parent
  # (cli_test runs cart_simulate) captures its stderr or ignores its exit status.
  ASAN_OPTIONS="$common:log_path=$reports/$name${extra:+:$extra}" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$reports/$name" \
    timeout "$limit" "$@" > "$log" 2>&1
  local status=$?
  local found
  found="$(find "$reports" -name "$name.*" -type f -size +0 | sort)"
  if [ "$status" -eq 0 ] && [ -z "$found" ] &&
    ! grep -qE "runtime error:|ERROR: (Address|Leak|UndefinedBehavior)Sanitizer" "$log"; then
    echo "sanitize: ok   $name ($((SECONDS - start)) s)"
    passed=$((passed + 1))
  else
    echo "sanitize: FAIL $name (exit $status, $((SECONDS - start)) s; log $log${found:+; reports $reports/$name.*})"
    # shellcheck disable=SC2086
    { [ -z "$found" ] || cat $found; cat "$log"; } |
      grep -E -A12 "runtime error:|ERROR: .*Sanitizer|FAILED|Failure" | head -n 40 | sed 's/^/    /'
    failed=$((failed + 1))
  fi
}

launched=()  # runs started by launch, in order, collected by collect
launch() {  # launch NAME TIMEOUT ASAN_EXTRA COMMAND...: run in the background, at most $parallel at once
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n; done
  ( run "$@" > "$logs/$1.verdict" 2>&1 ) &
  launched+=("$1")
}
collect() {  # waits for the launched runs; prints and counts their verdicts in launch order
  wait
  local name verdict seconds
  for name in "${launched[@]}"; do
    verdict="$(cat "$logs/$name.verdict")"
    echo "$verdict"
    seconds="$(sed -nE 's/^sanitize: (ok  |FAIL) [^ ]+ \((exit [0-9]+, )?([0-9]+) s.*/\3/p' <<< "$verdict" | head -n 1)"
    if [[ "$verdict" == "sanitize: ok   "* ]]; then
      passed=$((passed + 1))
      junit_cases+=("$name ${seconds:-0} ok $logs/$name.log")
    else
      failed=$((failed + 1))
      junit_cases+=("$name ${seconds:-0} FAIL $logs/$name.log")
    fi
  done
  launched=()
}

{  # every run starts with it (3 s): a check that cannot fail proves nothing
  # The net itself: small programs with the same flags, each with one defect, must each fail, also
  # when the defect is in a child whose parent exits 0 (ASan and LSan reports go to log_path files),
  # and a clean run of the same program must pass. Exits non-zero if a defect went unnoticed or the
  # clean run was judged a failure.
  # Limit, measured: GCC's libubsan beside libasan ignores log_path (its common flags are never
  # parsed as a plugin), so a UBSan report in a child is seen through the child's exit status 1
  # (halt_on_error). Every test that starts cart_simulate checks its status exactly, and
  # cart_simulate itself never exits 1 (0, 2, 3, 4, 5).
  echo "== self-check of the report detection"
  probe="$logs/probe"
  mkdir -p "$probe"
  cat > "$probe/defects.cpp" <<'PROBE'
#include <cstdlib>
#include <cstring>
#include <string>
int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  if (what == "child") {  // the parent ignores the child's exit status: only its report tells
    return std::system((std::string(argv[0]) + " " + argv[2] + " > /dev/null 2>&1").c_str()) * 0;
  }
  volatile int big = 2147483647;
  int* heap = new int[4];
  if (what == "freed") { delete[] heap; return heap[argc]; }     // ASan: heap-use-after-free
  if (what == "overflow") big = big + argc;                       // UBSan: signed integer overflow
  if (what == "cast") { volatile double d = 1e19; big = static_cast<int>(d); }  // float-cast-overflow
  if (what == "leak") { static char* volatile lost; lost = new char[64]; lost = nullptr; }  // LSan
  delete[] heap;
  return 0;
}
PROBE
  # shellcheck disable=SC2086
  if ! "$cxx" -std=c++17 $flags -Wno-overflow -fsanitize=address,undefined -o "$probe/defects" \
      "$probe/defects.cpp" > "$probe/build.log" 2>&1; then
    echo "sanitize: FAIL the self-check probe did not build (log $probe/build.log)"
    junit_cases+=("self_check 0 FAIL $probe/build.log")
    write_junit
    echo "0 passed, 1 failed"
    exit 1
  fi
  unnoticed=0
  for probe_case in "freed direct" "overflow direct" "cast direct" "leak direct" "freed child" "leak child"; do
    read -r defect how <<< "$probe_case"
    if [ "$how" = direct ]; then arguments=("$defect"); else arguments=(child "$defect"); fi
    output="$(run "probe_${defect}_$how" 60 "" "$probe/defects" "${arguments[@]}")"
    case "$output" in
      *"FAIL probe_"*) echo "sanitize: caught $defect ($how)" ;;
      *) echo "sanitize: MISSED $defect ($how): $output"; unnoticed=$((unnoticed + 1)) ;;
    esac
  done
  for how in direct child; do  # no defect: must pass, or every FAIL above proves nothing
    if [ "$how" = direct ]; then arguments=(clean); else arguments=(child clean); fi
    output="$(run "probe_clean_$how" 60 "" "$probe/defects" "${arguments[@]}")"
    case "$output" in
      *"ok   probe_"*) echo "sanitize: passed the clean run ($how)" ;;
      *) echo "sanitize: a clean run was judged a failure: $output"; unnoticed=$((unnoticed + 1)) ;;
    esac
  done
  if [ "$unnoticed" -ne 0 ]; then
    echo "sanitize: self-check FAILED"
    junit_cases+=("self_check 0 FAIL $logs/probe/build.log")
    write_junit
    echo "0 passed, 1 failed"
    exit 1
  fi
  echo "sanitize: self-check passed"
  junit_cases+=("self_check_detects_every_defect 0 ok $probe/build.log")
  passed=$((passed + 1))
  $self_check_only && { write_junit; exit 0; }
}

echo "== unit tests ($parallel at once)${left_out[1]:+; left out: ${left_out[*]:1}}"
for test in "${unit_tests[@]}"; do
  extra=""
  [ "$test" = bad_input_test ] && extra="quarantine_size_mb=1"
  if [ ! -x "$bin/$test" ]; then
    echo "sanitize: FAIL $test (not built)"
    failed=$((failed + 1))
    junit_cases+=("$test 0 FAIL $workspace/build.log")
    continue
  fi
  launch "$test" 1800 "$extra" "$bin/$test"
done
collect

echo "== cart_simulate on the shipped scenes"
for scene in "$repo"/config/scenes/*.yaml; do
  name="$(basename "$scene" .yaml)"
  launch "scene_$name" 600 "" "$bin/cart_simulate" --quiet --scene "$scene" --output "$logs/$name.csv"
done
collect

# Wall time of the build and of the runs, and the CPU time of everything this script started.
echo "sanitize: build $build_seconds s, runs $((SECONDS - runs_start)) s of wall time; CPU (user, system) of the script, then of its children:"
times
write_junit
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]

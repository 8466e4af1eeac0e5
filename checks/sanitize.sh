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
# One suppression, by name (checks/sanitize/lsan.supp): the rosbag::Bag that BagRecorder::close()
# lets go on purpose when closing it failed (its destructor would throw; see bag_recorder.cpp).
# bad_input_test's memory-growth check runs with a 1 MiB ASan quarantine (quarantine_size_mb=1):
# with the default 256 MiB quarantine every freed block stays resident and the flood would look
# like growth.
#
# Usage: checks/sanitize.sh [--compiler gcc|clang] [--no-build] [--self-check]
#        (default gcc, the project's compiler; with clang the build stops at clang-only warnings,
#        since the package builds with -Werror; --self-check only proves the report detection, 3 s)
# Prints "N passed, N failed" and the wall and CPU time; exits non-zero on any failure or report.
# Measured on the shared 2-core machine (docs/developing.md): from scratch 41 min 39 s of wall time
# (1868 s CPU; the build ~29 min of it, niced beside other builds); with a warm ccache and few changed
# files 16 min 9 s (build 155 s, the 45 runs 814 s, one at a time).
set -uo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="/usr/bin:/bin:$PATH"
compiler=gcc
build=true
self_check_only=false
while [ $# -gt 0 ]; do
  case "$1" in
    --compiler) compiler="${2:-}"; shift 2 ;;
    --no-build) build=false; shift ;;  # run what the last build left (a missing test fails)
    --self-check) self_check_only=true; build=false; shift ;;  # only prove that reports are caught
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
flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer -g -O1"
[ "$compiler" = gcc ] && flags="$flags -Wno-maybe-uninitialized"

unit_tests=()
for source in "$repo"/test/unit/*_test.cpp "$repo"/test/ros_unit/*_test.cpp; do
  test="$(basename "$source" .cpp)"
  # install_space_test installs a fully built workspace (cart_sim too): not a memory check.
  [ "$test" = install_space_test ] || unit_tests+=("$test")
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
if [ "$build_status" -ne 0 ]; then
  grep -E "error|Error" "$workspace/build.log" | head -n 30
  echo "sanitize: build failed (log: $workspace/build.log)"
  echo "0 passed, 1 failed"
  exit 1
fi

runs_start=$SECONDS
bin="$workspace/devel/lib/birkhoff_cart"
logs="$workspace/logs"
reports="$logs/reports"  # every sanitizer report of every process, children included
rm -rf "$logs"
mkdir -p "$reports"
suppressions="$repo/checks/sanitize/lsan.supp"
common="abort_on_error=0:halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$suppressions:print_suppressions=0"
passed=0
failed=0
# Exactly one suppression, the one named above: anything more must be argued here first.
entries="$(grep -cvE '^[[:space:]]*(#|$)' "$suppressions")"
if [ "$entries" != 1 ] || ! grep -qx 'leak:birkhoff_cart::BagRecorder::close' "$suppressions"; then
  echo "sanitize: FAIL $suppressions must hold exactly the one entry leak:birkhoff_cart::BagRecorder::close (has $entries)"
  failed=$((failed + 1))
fi
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

{  # every run starts with it (3 s): a check that cannot fail proves nothing
  # The net itself: small programs with the same flags, each with one defect, must each fail, also
  # when the defect is in a child whose parent exits 0 (ASan and LSan reports go to log_path files);
  # the suppressed leak must pass. Exits non-zero if a defect went unnoticed.
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
namespace birkhoff_cart { struct BagRecorder { static void close(); }; }
__attribute__((noinline)) void birkhoff_cart::BagRecorder::close() { static char* volatile kept; kept = new char[64]; kept = nullptr; }
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
  if (what == "suppressed") birkhoff_cart::BagRecorder::close();  // the named suppression
  delete[] heap;
  return 0;
}
PROBE
  # shellcheck disable=SC2086
  if ! "$cxx" -std=c++17 $flags -Wno-overflow -fsanitize=address,undefined -o "$probe/defects" \
      "$probe/defects.cpp" > "$probe/build.log" 2>&1; then
    echo "sanitize: FAIL the self-check probe did not build (log $probe/build.log)"
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
  output="$(run probe_suppressed 60 "" "$probe/defects" suppressed)"
  case "$output" in
    *"ok   probe_"*) echo "sanitize: passed the suppressed leak in birkhoff_cart::BagRecorder::close" ;;
    *) echo "sanitize: the named suppression did not hold: $output"; unnoticed=$((unnoticed + 1)) ;;
  esac
  if [ "$failed" -ne 0 ] || [ "$unnoticed" -ne 0 ]; then
    echo "sanitize: self-check FAILED"
    echo "0 passed, 1 failed"
    exit 1
  fi
  echo "sanitize: self-check passed"
  $self_check_only && exit 0
}

echo "== unit tests"
for test in "${unit_tests[@]}"; do
  extra=""
  [ "$test" = bad_input_test ] && extra="quarantine_size_mb=1"
  if [ ! -x "$bin/$test" ]; then
    echo "sanitize: FAIL $test (not built)"
    failed=$((failed + 1))
    continue
  fi
  run "$test" 1800 "$extra" "$bin/$test"
done

echo "== cart_simulate on the shipped scenes"
for scene in "$repo"/config/scenes/*.yaml; do
  name="$(basename "$scene" .yaml)"
  run "scene_$name" 600 "" "$bin/cart_simulate" --quiet --scene "$scene" --output "$logs/$name.csv"
done

# Wall time of the build and of the runs, and the CPU time of everything this script started.
echo "sanitize: build $build_seconds s, runs $((SECONDS - runs_start)) s of wall time; CPU (user, system) of the script, then of its children:"
times
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]

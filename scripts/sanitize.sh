#!/usr/bin/env bash
# Sanitizers as a habit: builds the core, the CLI, the unit tests and the ROS-layer unit tests with
# AddressSanitizer + UndefinedBehaviorSanitizer + float-cast-overflow (GCC has it but leaves it out
# of -fsanitize=undefined; clang includes it: named explicitly for both) in a workspace of its own
# (.ws_sanitize_<compiler>/, never .ws/), runs every one of those tests and cart_simulate on every
# shipped scene (config/scenes/*.yaml, full duration), and fails on any report: the first UBSan
# report aborts the process (-fno-sanitize-recover=all), ASan aborts on its first error, LSan
# fails the process at exit; the logs are also searched for a report.
#
# One suppression, by name (scripts/sanitize/lsan.supp): the rosbag::Bag that BagRecorder::close()
# lets go on purpose when closing it failed (its destructor would throw; see bag_recorder.cpp).
# bad_input_test's memory-growth check runs with a 1 MiB ASan quarantine (quarantine_size_mb=1):
# with the default 256 MiB quarantine every freed block stays resident and the flood would look
# like growth.
#
# Usage: scripts/sanitize.sh [--compiler gcc|clang] [--no-build]   (default gcc, the project's compiler; with
#        clang the build stops at clang-only warnings, since the package builds with -Werror)
# Prints "N passed, N failed"; exits non-zero on any failure or report. About 12 min on 2 cores
# from scratch (ccache makes a rebuild quick); the run itself about 6 min.
set -uo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="/usr/bin:/bin:$PATH"
compiler=gcc
build=true
while [ $# -gt 0 ]; do
  case "$1" in
    --compiler) compiler="${2:-}"; shift 2 ;;
    --no-build) build=false; shift ;;  # run what the last build left (a missing test fails)
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

echo "== build ($compiler: $flags) in $workspace"
# Configure with catkin_make (and build the core), then make the wanted targets through CMake's Makefile2:
# the top-level Makefile builds its goals one after another, Makefile2 builds them in parallel.
targets=()
for target in birkhoff_cart_core cart_simulate "${unit_tests[@]}"; do
  targets+=("birkhoff_cart/CMakeFiles/$target.dir/all")
done
set +u
build_status=0
if $build; then (
  cd "$workspace" &&
    catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=None \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
      -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -j2 --make-args birkhoff_cart_core &&
    make -C build -f CMakeFiles/Makefile2 -j2 "${targets[@]}"
) > "$workspace/build.log" 2>&1 || build_status=$?; fi
set -u
if [ "$build_status" -ne 0 ]; then
  grep -E "error|Error" "$workspace/build.log" | head -n 30
  echo "sanitize: build failed (log: $workspace/build.log)"
  echo "0 passed, 1 failed"
  exit 1
fi

bin="$workspace/devel/lib/birkhoff_cart"
logs="$workspace/logs"
rm -rf "$logs"
mkdir -p "$logs"
common="abort_on_error=0:halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$repo/scripts/sanitize/lsan.supp:print_suppressions=0"
passed=0
failed=0
run() {  # run NAME TIMEOUT ASAN_EXTRA COMMAND...: one sanitized run, judged by exit status and log
  local name="$1" limit="$2" extra="$3"
  shift 3
  local log="$logs/$name.log"
  local start=$SECONDS
  ASAN_OPTIONS="$common${extra:+:$extra}" timeout "$limit" "$@" > "$log" 2>&1
  local status=$?
  if [ "$status" -eq 0 ] && ! grep -qE "runtime error:|ERROR: (Address|Leak|UndefinedBehavior)Sanitizer" "$log"; then
    echo "sanitize: ok   $name ($((SECONDS - start)) s)"
    passed=$((passed + 1))
  else
    echo "sanitize: FAIL $name (exit $status, $((SECONDS - start)) s; log $log)"
    grep -E -A12 "runtime error:|ERROR: .*Sanitizer|FAILED|Failure" "$log" | head -n 40 | sed 's/^/    /'
    failed=$((failed + 1))
  fi
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

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]

#!/usr/bin/env bash
# Fuzzes the scene reader for a fixed time budget (docs/accuracy.md §3).
#
# With clang's libFuzzer (Debian: clang-14 and libclang-rt-14-dev) the target
# test/fuzz/scene_reader_fuzz.cpp is built with -fsanitize=fuzzer,address,undefined together with
# the core sources, seeded with config/scenes/*.yaml and a dictionary of the scene keys, and run
# for the budget; without clang a mutation loop over the shipped scenes (the same target built with
# g++ and -DSCENE_FUZZ_MUTATION_LOOP) runs instead.
#
# Usage: checks/fuzz_scenes.sh [SECONDS (default 120)] [JOBS (default 1)]
# Findings (crashes, sanitizer reports, hangs past 10 s, non-SceneError exceptions) are written to
# $out/findings/ (out = .fuzz/ in the repository); the script exits 1 when there is one. Turn each
# into a file under test/fuzz/regressions/ (scene_fuzz_regression_test runs them all).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
budget="${1:-120}"
jobs="${2:-1}"
out="$repo/.fuzz"
mkdir -p "$out/corpus" "$out/findings"
cp "$repo"/config/scenes/*.yaml "$out/corpus/"

mapfile -t core_sources < <(find "$repo/src/core" -name "*.cpp" | sort)
includes=(-I"$repo/include" -I"$repo/src/core" -isystem /usr/include/eigen3)

# A dictionary of the scene's keys and words speeds the fuzzer past the key checks.
dictionary="$out/scene.dict"
grep -ohE '^ *[a-z_0-9]+:' "$repo"/config/scenes/*.yaml | tr -d ' :' | sort -u | sed 's/.*/"&:"/' > "$dictionary"
for word in birkhoff2 birkhoff4 rk2 rk4 dopri5 midpoint autonomous paper none shadow_run paper_analytic \
            constant cosine step ramp smooth_switch_off command off warn error true false .inf .nan; do
  echo "\"$word\"" >> "$dictionary"
done

if command -v clang++ >/dev/null && echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, long) { return 0; }' |
     clang++ -fsanitize=fuzzer -x c++ - -o "$out/probe" 2>/dev/null; then
  binary="$out/scene_reader_fuzz"
  if [ ! -x "$binary" ] || [ -n "$(find "$repo/src/core" "$repo/include" "$repo/test/fuzz" -newer "$binary" -name '*.[ch]*' | head -1)" ]; then
    echo "fuzz_scenes: building the libFuzzer target (clang++, ASan + UBSan)"
    clang++ -std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
      "${includes[@]}" "$repo/test/fuzz/scene_reader_fuzz.cpp" "${core_sources[@]}" -lyaml-cpp -o "$binary"
  fi
  echo "fuzz_scenes: libFuzzer for ${budget} s on $jobs job(s), seeds: $(ls "$out/corpus" | wc -l) files"
  set +e
  (cd "$out/findings" && "$binary" -max_total_time="$budget" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
     -dict="$dictionary" -jobs="$jobs" -workers="$jobs" -print_final_stats=1 "$out/corpus" 2>&1 | tee "$out/last_run.log" |
     grep -E "^#[0-9]+.*(DONE|pulse)|stat::|ERROR|FINDING|SUMMARY|Test unit written|Done [0-9]+ runs" )
  status=${PIPESTATUS[0]}
  set -e
else
  binary="$out/scene_reader_fuzz_loop"
  echo "fuzz_scenes: no libFuzzer; building the mutation loop (g++)"
  g++ -std=c++17 -O2 -DSCENE_FUZZ_MUTATION_LOOP "${includes[@]}" "$repo/test/fuzz/scene_reader_fuzz.cpp" \
    "${core_sources[@]}" -lyaml-cpp -o "$binary"
  set +e
  (cd "$out/findings" && timeout $((budget + 60)) "$binary" "$budget" 1 "$repo"/config/scenes/*.yaml)
  status=$?
  set -e
fi
findings=$(find "$out/findings" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' -o -name 'scene_fuzz_last_input.yaml' \) | wc -l)
echo "fuzz_scenes: exit status $status, $findings finding file(s) in $out/findings"
[ "$status" -eq 0 ] && [ "$findings" -eq 0 ]

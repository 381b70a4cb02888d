#!/usr/bin/env bash
# Sanitizer and fuzzing runs (docs/RELIABILITY.md). Installs what it needs (Debian packages),
# builds the preset into its own folder and runs it:
#   bash scripts/sanitize.sh asan            # whole suite under ASan + UBSan (minus the whole-brain runs)
#   bash scripts/sanitize.sh asan-core       # CI's subset: the library's test programs (no CLI, viewer, GL)
#   bash scripts/sanitize.sh tsan            # the multithreaded parts under ThreadSanitizer
#   bash scripts/sanitize.sh fuzz [SECONDS]  # each libFuzzer target for SECONDS (default 60)
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-asan}

need=()
case "$mode" in
  fuzz) need=(clang libclang-rt-14-dev) ;;
esac
missing=()
for p in "${need[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs=$(nproc 2>/dev/null || echo 2)

# Runs `FN NAME` for each NAME, at most $jobs at a time (each writes its own log); waits for all,
# then fails when any failed.
in_parallel() {
  local fn=$1 failed=0 pid
  shift
  local pids=()
  for name in "$@"; do
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
    "$fn" "$name" &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
  return "$failed"
}

# One library test program under ASan + UBSan (asan-core), its output kept in a log shown on failure.
asan_core_one() {
  local t=$1 start=$SECONDS log="build-asan/asan_core_$1.log"
  # Left to the release suite: the whole-brain runs, and the whole-phantom segmentations and
  # repair whose code paths the BrainWeb slab and the small repair cases already run sanitized
  # (each 1-2 min under ASan; docs/RELIABILITY.md).
  if "build-asan/tests/$t/${t}_tests" --gtest_filter="-$asan_core_skip" --gtest_brief=1 >"$log" 2>&1; then
    echo "asan-core: ${t}_tests passed in $((SECONDS - start)) s" >&2
  else
    tail -60 "$log" >&2
    echo "asan-core: ${t}_tests FAILED after $((SECONDS - start)) s (log: $log)" >&2
    return 1
  fi
}

# One libFuzzer target for $seconds (fuzz), "TARGET:SEEDS" (seed corpus folder under fuzz/corpus).
fuzz_one() {
  local target=${1%%:*} seeds=${1#*:} rc=0 runs
  local corpus="build-fuzz/corpus/$target" log="build-fuzz/fuzz_$target.log"
  mkdir -p "$corpus"
  "build-fuzz/fuzz/fuzz_$target" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="build-fuzz/findings/$target-" "$corpus" "fuzz/corpus/$seeds" >"$log" 2>&1 || rc=$?
  runs=$(grep -m1 '^stat::number_of_executed_units' "$log" | awk '{print $2}' || true)
  echo "fuzz_$target: ${seconds} s, ${runs:-?} executions, exit $rc" >&2
  if [ "$rc" -ne 0 ]; then
    grep -E "ERROR|SUMMARY|Test unit written" "$log" >&2 || tail -20 "$log" >&2
    return 1
  fi
}

case "$mode" in
  asan-core)
    # The library's own test programs (atomic file writer, grid, level set, mesher, segmentation, swarm, evaluation,
    # phantom, session, image IO), each run whole in one process; the CLI, viewer and rendering
    # tests (which need the whole sanitized `liveset` binary) run with `asan`.
    # Longest first (docs/RELIABILITY.md), so that two at a time finish together.
    core=(segment levelset swarm session mesh io phantom eval grid base)
    asan_core_skip='BrainWebRepair.*:BrainWeb.WholeBrain*:BrainWeb.SeedsAloneFollow*:BrainWeb.TheAutomaticCurvature*:PhantomSegmentation.*:Repair.SwarmClosesThePhantomPerforations'
    cmake --preset asan >/dev/null
    cmake --build --preset asan -j "$jobs" --target "${core[@]/%/_tests}"
    export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    export LSAN_OPTIONS=suppressions=$PWD/tests/sanitizer/lsan.supp
    # $jobs (nproc) programs at a time, each mostly single-threaded; a failed one's log is printed.
    in_parallel asan_core_one "${core[@]}"
    ;;
  asan)
    cmake --preset asan >/dev/null
    cmake --build --preset asan -j "$jobs"
    ctest --preset asan
    ;;
  tsan)
    # Debian's libtbb is not built with ThreadSanitizer, so TSan cannot see the scheduler's
    # synchronisation (every parallel_for would be reported). Build the same oneTBB from Debian's
    # source package with -fsanitize=thread, once, into build-tsan-deps, and link the tests to it.
    deps=$PWD/build-tsan-deps
    tbb=$deps/onetbb-tsan
    if [ ! -f "$tbb/lib/cmake/TBB/TBBConfig.cmake" ]; then
      sudo_cmd=()
      [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
      if ! apt-get source --print-uris onetbb >/dev/null 2>&1; then
        printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
          "${sudo_cmd[@]}" tee /etc/apt/sources.list.d/liveset-deb-src.sources >/dev/null
        "${sudo_cmd[@]}" apt-get update -qq
      fi
      dpkg-query -W -f='${Status}' dpkg-dev 2>/dev/null | grep -q "install ok installed" ||
        DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends dpkg-dev >/dev/null
      mkdir -p "$deps"
      (cd "$deps" && rm -rf onetbb-*/ && apt-get source -qq onetbb >/dev/null 2>&1)
      src=$(find "$deps" -maxdepth 1 -type d -name 'onetbb-[0-9]*' | head -1)
      cmake -S "$src" -B "$deps/tbb-build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF \
        -DTBBMALLOC_BUILD=OFF -DTBB_STRICT=OFF -DCMAKE_CXX_FLAGS=-fsanitize=thread -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread \
        -DCMAKE_INSTALL_PREFIX="$tbb" >/dev/null
      cmake --build "$deps/tbb-build" -j "$jobs" >/dev/null
      cmake --install "$deps/tbb-build" >/dev/null
    fi
    # Only the test programs holding the multithreaded parts (the ctest preset's filter).
    cmake --preset tsan -DTBB_DIR="$tbb/lib/cmake/TBB" >/dev/null
    cmake --build --preset tsan -j "$jobs" --target levelset_tests mesh_tests segment_tests swarm_tests
    ctest --preset tsan
    ;;
  fuzz)
    seconds=${2:-60}
    cmake --preset fuzz >/dev/null
    cmake --build --preset fuzz -j "$jobs"
    mkdir -p build-fuzz/findings
    # $jobs (nproc) targets at a time, one per core: each still fuzzes for $seconds on a core of its own.
    in_parallel fuzz_one mesh_readers:mesh image_checks:image recovery_file:recovery session_script:script
    ;;
  *) echo "usage: scripts/sanitize.sh asan|asan-core|tsan|fuzz [SECONDS]" >&2; exit 2 ;;
esac

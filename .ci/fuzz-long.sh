#!/usr/bin/env bash
# The long fuzzing run: each target of tests/fuzz for a while (default 10
# minutes) under libFuzzer (stable Rust, no sanitizer), starting from the
# committed corpus, which it copies (new inputs go to target/fuzz-corpus, not
# into the repository). Needs cargo-bolero:
#   cargo install cargo-bolero --no-default-features
#
#   .ci/fuzz-long.sh [SECONDS] [TARGET...]
#
# Prints, per target, the runs done and whether any input crashed (a panic,
# an abort) or timed out (a hang of more than 60 s on one input).
set -uo pipefail
cd "$(dirname "$0")/.."
secs=${1:-600}; shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_params_toml fuzz_machine_toml fuzz_tables fuzz_rhai_family fuzz_plugin_descriptor fuzz_export_report fuzz_damaged_plugin)
status=0
for t in "${targets[@]}"; do
  name=${t#fuzz_}
  corpus=target/fuzz-corpus/$name
  crashes=target/fuzz-crashes/$name
  mkdir -p "$corpus" "$crashes"
  cp tests/fuzz/tests/__fuzz__/"$name"/corpus/* "$corpus"/
  log=target/fuzz-$name.log
  cargo bolero test -p pilgrim-fuzz "$t" --sanitizer NONE -T "${secs}s" \
    --corpus-dir "$corpus" --crashes-dir "$crashes" -E=-timeout=60 -E=-rss_limit_mb=8192 >"$log" 2>&1
  rc=$?
  runs=$(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "$log" | tail -1)
  found=$(ls "$crashes" 2>/dev/null | wc -l)
  echo "$t: ${runs:-no summary} ; exit $rc ; crash/timeout inputs: $found"
  [ "$rc" -eq 0 ] && [ "$found" -eq 0 ] || status=1
done
exit $status

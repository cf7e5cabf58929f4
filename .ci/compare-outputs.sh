#!/usr/bin/env bash
# Compares every output of the default mandrel job, its two example
# parameter files and the demo between a base commit and the working tree:
# byte for byte, file by file. Builds the base in a throw-away worktree
# (its own target directory under target/compare-base).
#
#   .ci/compare-outputs.sh BASE_COMMIT
#
# Exits non-zero and lists the files that differ.
set -euo pipefail
base=${1:?usage: .ci/compare-outputs.sh BASE_COMMIT}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
work=$(mktemp -d)
trap 'git worktree remove --force "$work/src" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git worktree add --detach "$work/src" "$base" >/dev/null
CARGO_TARGET_DIR="$root/target/compare-base" cargo build --release --quiet --bin pilgrim --manifest-path "$work/src/Cargo.toml"
cargo build --release --quiet --bin pilgrim
jobs=(
  "mandrel|scripts/mandrel.rhai"
  "small|scripts/mandrel.rhai --params scripts/examples/mandrel-small.toml"
  "large|scripts/mandrel.rhai --params scripts/examples/mandrel-large.toml"
  "demo|scripts/examples/mill_circle.rhai"
)
run_all() { # binary, source tree, output root
  for j in "${jobs[@]}"; do
    name=${j%%|*}; args=${j#*|}
    (cd "$2" && "$1" run $args --quiet --out "$3/$name")
  done
}
# Each runs from its own tree, with its own scripts and examples (run with
# the same relative paths, which the reports record).
run_all "$root/target/compare-base/release/pilgrim" "$work/src" "$work/base"
run_all "$root/target/release/pilgrim" "$root" "$work/new"
status=0
for j in "${jobs[@]}"; do
  name=${j%%|*}
  for f in $( (cd "$work/base/$name" && ls; cd "$work/new/$name" && ls) | sort -u); do
    if ! cmp -s "$work/base/$name/$f" "$work/new/$name/$f"; then
      status=1
      case "$f" in
        *.csv)
          if python3 -c 'import csv,sys; r=lambda p: list(csv.reader(open(p))); sys.exit(r(sys.argv[1]) != r(sys.argv[2]))' \
              "$work/base/$name/$f" "$work/new/$name/$f"; then
            echo "differs: $name/$f (bytes only: the same CSV records)"
          else
            echo "differs: $name/$f (records)"
          fi ;;
        *.json)
          echo "differs: $name/$f:"
          diff "$work/base/$name/$f" "$work/new/$name/$f" | sed 's/^/    /' | head -20 ;;
        *) echo "differs: $name/$f" ;;
      esac
    fi
  done
done
if [ $status -eq 0 ]; then
  echo "all outputs byte-identical to $base ($(cd "$work/new" && find . -type f | wc -l) files)"
fi
exit $status

#!/usr/bin/env bash
# Seeds the fuzz corpora from the test fixtures: programs and their compiled modules
# (compile, load_bytecode), the `.case` files of tests/errors and tests/runs and the
# example workcells bundled in the same format (workcell, run), the built-in robots' URDFs
# and the test meshes (urdf), and the logs of small runs (log).
set -euo pipefail
shopt -s nullglob
cd "$(dirname "$0")/.."
for c in compile rapid load_bytecode workcell run urdf log; do mkdir -p "fuzz/corpus/$c"; done
cp crates/wslc/test_data/ok/*.wsl crates/wslc/test_data/err/*.wsl crates/wslc/test_data/spec/*.wsl fuzz/corpus/compile/
# RAPID: the fixtures, the example workcells' modules and the vendored corpus.
cp crates/wslc/test_data/ok/*.mod crates/wslc/test_data/err/*.mod workcells/*/*.mod fuzz/corpus/rapid/
find tests/rapid/corpus tests/rapid/public -type f \( -iname '*.mod' -o -iname '*.sys' -o -iname '*.prg' -o -iname '*.modx' \) -exec cp {} fuzz/corpus/rapid/ \; 2>/dev/null || true
cargo build -q -p vworks-cli
for f in crates/wslc/test_data/ok/*.wsl; do
  ./target/debug/vworks build "$f" -o "fuzz/corpus/load_bytecode/$(basename "$f" .wsl).wslb" 2>/dev/null
done
# Cells: the `.case` files as they are; each example workcell as one bundle.
for f in tests/errors/cell-*.case tests/runs/*.case tests/rapid/*.case; do
  cp "$f" "fuzz/corpus/workcell/$(basename "$f")"
  cp "$f" "fuzz/corpus/run/$(basename "$f")"
done
for d in workcells/*/; do
  name=$(basename "$d")
  { for f in "$d"cell.toml "$d"*.wsl "$d"*.mod; do echo "--- $(basename "$f")"; cat "$f"; done; } > "fuzz/corpus/workcell/wc-$name"
  cp "fuzz/corpus/workcell/wc-$name" "fuzz/corpus/run/wc-$name"
done
# URDFs (first byte even: URDF text) and meshes (odd: 1 STL, 3 OBJ).
for f in crates/model/models/*.urdf; do
  { printf '\x00'; cat "$f"; } > "fuzz/corpus/urdf/$(basename "$f")"
done
find crates tests -name '*.stl' -size -64k | while read -r f; do
  { printf '\x01'; cat "$f"; } > "fuzz/corpus/urdf/$(basename "$f")"
done
find crates tests -name '*.obj' -size -64k | while read -r f; do
  { printf '\x03'; cat "$f"; } > "fuzz/corpus/urdf/$(basename "$f")"
done
# Logs of small runs (a few kB each).
tmp=$(mktemp -d)
for f in tests/runs/parallel-inner-join.case tests/runs/timed-wait-then-deadlock.case tests/runs/race-plain-read.case; do
  rm -rf "$tmp"/*
  awk -v dir="$tmp" '/^--- /{out=dir"/"substr($0,5); next} out{print > out}' "$f"
  (cd "$tmp" && "$OLDPWD/target/debug/vworks" run cell.toml --log run.mcap --quiet >/dev/null 2>&1 || true)
  [ -f "$tmp/run.mcap" ] && cp "$tmp/run.mcap" "fuzz/corpus/log/$(basename "$f" .case).mcap"
done
rm -rf "$tmp"

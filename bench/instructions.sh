#!/usr/bin/env bash
# Instruction counts (valgrind's callgrind) of the engine's workloads: deterministic where
# wall times on a shared machine differ by 10–30 % between runs, so two commits compare
# to a fraction of a percent. Run it in each checkout and compare the tables:
#
#     bench/instructions.sh            # builds the examples (release), prints the table
#
# Each count is the whole process (loading the cell, compiling its programs, the runs).
#   ping-pong    2 robots, 20,000 signal round trips, twice (the events bench's ping_pong)
#   ring4        4 robots taking turns through a global with wait_until, 5,000 rounds, twice
#   grid4        the 4-robot minute (bench/cells/grid4), once
#   weldline     workcells/weldline, once
#   grid16/64    the scaling bench's (d): 16 and 64 arms for 4 simulated s, three runs
#   grid4-log    the 4-robot minute with the full MCAP log (the writer thread counted too)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "needs valgrind (apt-get install valgrind)" >&2; exit 2; }
cargo build -q --release -p vworks-se --example simulate --example grid
target=${CARGO_TARGET_DIR:-target}
bin="$target/release/examples"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cell() { # name, robot programs as NAME=FILE pairs
  local dir="$tmp/$1"; shift; mkdir -p "$dir"
  printf 'name = "events"\ncycle = "4ms"\n' > "$dir/cell.toml"
  local i=0
  for r in "$@"; do
    printf '[[robot]]\nname = "%s"\nmodel = "irb120"\nprogram = "%s.wsl"\nbase = { xyz = ["%dmm", "0mm", "0mm"] }\n' "$r" "$r" $((i * 2000)) >> "$dir/cell.toml"
    i=$((i + 1))
  done
}
cell pp a b
printf 'proc main() {\n    for i in 0..20000 {\n        signal b.ping;\n        wait_signal pong;\n    }\n}\n' > "$tmp/pp/a.wsl"
printf 'proc main() {\n    for i in 0..20000 {\n        wait_signal ping;\n        signal a.pong;\n    }\n}\n' > "$tmp/pp/b.wsl"
cell ring r0 r1 r2 r3
for k in 0 1 2 3; do
  printf 'global turn = 0;\nproc main() {\n    for i in 0..5000 {\n        wait_until turn == i * 4 + %d;\n        turn += 1;\n    }\n}\n' $k > "$tmp/ring/r$k.wsl"
done
count() { # label, command…
  local n
  n=$(valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "${@:2}" 2>&1 >/dev/null |
    awk '/Collected/ {print $4}')
  printf '%-10s %15s\n' "$1" "$n"
}
echo "workload   instructions"
count ping-pong "$bin/simulate" "$tmp/pp/cell.toml" 2
count ring4 "$bin/simulate" "$tmp/ring/cell.toml" 2
count grid4 "$bin/simulate" bench/cells/grid4/cell.toml 1
count weldline "$bin/simulate" workcells/weldline/cell.toml 1
count grid16 "$bin/grid" 16 2
count grid64 "$bin/grid" 64 2
count grid4-log "$bin/simulate" bench/cells/grid4/cell.toml 1 --log "$tmp/grid4.mcap"

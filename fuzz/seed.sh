#!/usr/bin/env bash
# Seeds the fuzz corpora from the golden test programs and their compiled modules.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p fuzz/corpus/compile fuzz/corpus/load_bytecode
cp crates/wslc/test_data/ok/*.wsl crates/wslc/test_data/err/*.wsl crates/wslc/test_data/spec/*.wsl fuzz/corpus/compile/
cargo build -q -p vworks-cli
for f in crates/wslc/test_data/ok/*.wsl; do
  ./target/debug/vworks build "$f" -o "fuzz/corpus/load_bytecode/$(basename "$f" .wsl).wslb" 2>/dev/null
done

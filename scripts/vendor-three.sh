#!/usr/bin/env bash
# Rebuilds crates/report/vendor/three/three.iife.min.js: three.js from npm, pinned, bundled
# by esbuild (pinned) into one minified script that defines the global `THREE`, so that
# the report can inline it (no CDN, no network when the report is opened). Needs Node and
# npm; checks the result against the checksum in crates/report/vendor/three/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."
THREE_VERSION=0.187.0
ESBUILD_VERSION=0.25.12
out="$PWD/crates/report/vendor/three"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
npm init -y >/dev/null
npm install --no-audit --no-fund --ignore-scripts "three@$THREE_VERSION" "esbuild@$ESBUILD_VERSION" >/dev/null
node node_modules/esbuild/install.js >/dev/null
# The core, and the one addon the report's 3D view uses (orbit, pan and zoom with the mouse).
cat > entry.js <<'JS'
export * from 'three';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
JS
node_modules/.bin/esbuild entry.js --bundle --minify --format=iife --global-name=THREE \
  --legal-comments=inline --target=es2020 --outfile=three.iife.min.js
cp three.iife.min.js "$out/three.iife.min.js"
cp node_modules/three/LICENSE "$out/LICENSE"
want="$(grep -o 'sha256 [0-9a-f]*' "$out/README.md" | cut -d' ' -f2)"
got="$(sha256sum "$out/three.iife.min.js" | cut -d' ' -f1)"
if [ "$want" != "$got" ]; then
  echo "three.iife.min.js: sha256 $got, README.md says $want (a different three.js or esbuild?)" >&2
  exit 1
fi
echo "three.js $THREE_VERSION vendored: sha256 $got"

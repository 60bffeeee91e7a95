#!/usr/bin/env bash
# Builds the WASM DSP core (skipped when up to date), the Node bundles, the browser build and
# the desktop shell's bundles in dist/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build-wasm.sh
node scripts/build-ts.mjs
node scripts/build-web.mjs
node scripts/build-electron.mjs

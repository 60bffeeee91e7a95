#!/usr/bin/env bash
# Sets up (first run only), builds, and serves the UI with the demo pipeline on simulated EMG
# (engine in the page's Web Worker). Extra arguments go to `mosaic web` (`npm start -- --port N`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec node dist/cli.mjs web "$@"

#!/usr/bin/env bash
# Sets up (first run only), builds, and runs the demo pipeline on simulated EMG.
# Extra arguments go to `mosaic run` (e.g. `npm start -- --duration 10`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec node dist/cli.mjs run pipelines/demo.yaml "$@"

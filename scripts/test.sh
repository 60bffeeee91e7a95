#!/usr/bin/env bash
# The whole test suite: setup (idempotent), lint, format, types, Rust, fixtures, unit and
# integration tests. This is what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=node_modules/.bin
step() { printf '\n\033[1m== %s\033[0m\n' "$*"; }

step "setup and build"
bash scripts/setup.sh

step "lint (eslint, with the layering rule)"
"$bin/eslint" --max-warnings 0 .

step "format (prettier)"
"$bin/prettier" --check --log-level warn .

step "types (tsc, per runtime layer)"
"$bin/tsc" -p tsconfig.pure.json
"$bin/tsc" -p tsconfig.node.json
"$bin/tsc" -p tsconfig.web.json
"$bin/tsc" -p tsconfig.webworker.json

step "rust (fmt, clippy, tests)"
cargo fmt --manifest-path core-wasm/Cargo.toml --all -- --check
cargo clippy --quiet --manifest-path core-wasm/Cargo.toml --workspace --all-targets -- -D warnings
cargo test --quiet --manifest-path core-wasm/Cargo.toml --workspace
# The Rust block template (mosaic new-block --rust): its kernel, reference and ABI tests.
cargo fmt --manifest-path templates/rust-block/Cargo.toml -- --check
cargo clippy --quiet --manifest-path templates/rust-block/Cargo.toml --all-targets -- -D warnings
cargo test --quiet --manifest-path templates/rust-block/Cargo.toml

step "reference fixtures are reproduced by their committed generators"
bash scripts/check-fixtures.sh

step "python (the sidecar package and the example modules, pytest)"
UV_PYTHON_DOWNLOADS=never python3 -m uv run --quiet --frozen --project native-bridges/python \
  --python python3.11 python -m pytest -q -p no:cacheprovider native-bridges/python/tests pipelines/python/tests

step "unit and integration tests (vitest)"
"$bin/vitest" run --exclude 'tests/e2e/**' --exclude 'tests/integration/status-realtime.test.ts' \
  --exclude 'tests/integration/lossless.test.ts'

# Tests that judge real-time status and the live UI's timing run one file at a time: on two
# cores, a neighbouring test's load (Chromium, a busy-looping block) would make them lag. The
# lossless test brings its own CPU-burning neighbour, which would slow the others.
step "real-time status, lossless acquisition and browser end-to-end tests (one file at a time)"
"$bin/vitest" run --maxWorkers 1 tests/e2e tests/integration/status-realtime.test.ts \
  tests/integration/lossless.test.ts

printf '\n\033[1;32mall tests passed\033[0m\n'

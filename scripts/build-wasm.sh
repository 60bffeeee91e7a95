#!/usr/bin/env bash
# Builds the Rust DSP core to WebAssembly and generates the JS glue:
#   core-wasm/pkg/mosaic_core.js + mosaic_core_bg.wasm (+ .d.ts files)
# Does nothing when the outputs are newer than every source, manifest and
# lock file of core-wasm/ (pass --force to rebuild anyway).
# Usage: bash scripts/build-wasm.sh [--force]   (from any directory)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CORE="$ROOT/core-wasm"
PKG="$CORE/pkg"
WANT_BINDGEN="0.2.130" # must equal the wasm-bindgen crate pin in core-wasm/bindings/Cargo.toml
OUT_JS="$PKG/mosaic_core.js"
OUT_WASM="$PKG/mosaic_core_bg.wasm"

force=0
if [[ "${1:-}" == "--force" ]]; then force=1; fi

stale() {
  [[ $force == 1 ]] && return 0
  [[ -f "$OUT_JS" && -f "$OUT_WASM" ]] || return 0
  local oldest="$OUT_JS"
  [[ "$OUT_WASM" -ot "$OUT_JS" ]] && oldest="$OUT_WASM"
  local newer
  newer="$(find "$CORE"/*/src "$CORE"/*/Cargo.toml "$CORE/Cargo.toml" "$CORE/Cargo.lock" \
    "${BASH_SOURCE[0]}" -type f -newer "$oldest" -print -quit 2>/dev/null || true)"
  [[ -n "$newer" ]]
}

if ! stale; then
  echo "build-wasm: core-wasm/pkg is up to date ($(wc -c <"$OUT_WASM") bytes of wasm)"
  exit 0
fi

# The CLI must match the crate version exactly, or the glue will not fit the module.
BINDGEN="$(command -v wasm-bindgen || true)"
if [[ -z "$BINDGEN" && -x "${CARGO_HOME:-$HOME/.cargo}/bin/wasm-bindgen" ]]; then
  BINDGEN="${CARGO_HOME:-$HOME/.cargo}/bin/wasm-bindgen"
fi
have="$("${BINDGEN:-wasm-bindgen}" --version 2>/dev/null | awk '{print $2}' || true)"
if [[ "$have" != "$WANT_BINDGEN" ]]; then
  echo "build-wasm: error: wasm-bindgen CLI ${WANT_BINDGEN} is required, found '${have:-none}'." >&2
  echo "build-wasm: run 'npm run setup' (it installs it with: cargo install wasm-bindgen-cli --version ${WANT_BINDGEN})." >&2
  exit 1
fi

echo "build-wasm: cargo build (wasm32-unknown-unknown, release, simd128)"
RUSTFLAGS="-C target-feature=+simd128" cargo build \
  --manifest-path "$CORE/Cargo.toml" -p mosaic-core-wasm \
  --release --target wasm32-unknown-unknown

WASM_IN="$CORE/target/wasm32-unknown-unknown/release/mosaic_core_wasm.wasm"
echo "build-wasm: wasm-bindgen --target web"
"$BINDGEN" --target web --out-dir "$PKG" --out-name mosaic_core "$WASM_IN"
# wasm-bindgen keeps the input's timestamps semantics loose; make the outputs
# strictly newer than the sources so the next run is a no-op.
touch "$OUT_WASM" "$OUT_JS"
echo "build-wasm: wrote core-wasm/pkg/mosaic_core.js and mosaic_core_bg.wasm ($(wc -c <"$OUT_WASM") bytes)"

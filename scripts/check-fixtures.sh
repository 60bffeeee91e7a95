#!/usr/bin/env bash
# Regenerates every reference fixture into a temporary folder with the pinned
# Python environment (tests/reference, managed by uv) and compares it byte for
# byte with the committed fixture, so the committed generators provably produce
# the committed fixtures. Exit 0 when all match, 1 on a mismatch, 2 when the
# environment cannot be set up.
# Usage: bash scripts/check-fixtures.sh   (from any directory)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PROJECT="$ROOT/tests/reference"

# Generator script -> the fixture files it writes (relative to the script's folder).
GENERATORS=(
  "core-wasm/dsp/tests/fixtures/gen_lfilter.py:lfilter.json"
  "core-wasm/dsp/tests/fixtures/gen_function.py:function.json"
  "core-wasm/dsp/tests/fixtures/gen_features.py:features.json"
  "core-wasm/dsp/tests/fixtures/gen_window.py:window.json"
  "core-wasm/dsp/tests/fixtures/gen_adaptive.py:adaptive.json"
  "core-wasm/dsp/tests/fixtures/gen_artifact.py:artifact.json"
  "core-wasm/learn/tests/fixtures/gen_learn.py:learn.json"
  "core-wasm/learn/tests/fixtures/gen_emg_regression.py:emg_regression.json"
  "core-wasm/learn/tests/fixtures/gen_lda.py:lda.json"
  "templates/rust-block/tests/fixtures/gen_tkeo.py:tkeo.json"
  "app/blocks/signal/fixtures/gen_dds.py:dds.json"
  "app/blocks/signal/fixtures/gen_envelope.py:envelope_5hz.csv"
  "app/blocks/kinematics/fixtures/gen_body_rig.py:body_rig.json"
  "app/ui/panels/fixtures/gen_training_metrics.py:training_metrics.json"
  "app/ui/panels/fixtures/gen_spectrum.py:spectrum.json"
)

# uv as installed by scripts/setup.sh (pip --user: `python3 -m uv`), or on PATH.
want_uv="$(tr -d '[:space:]' <"$PROJECT/UV_VERSION")"
if python3 -m uv --version >/dev/null 2>&1; then
  UV=(python3 -m uv)
elif command -v uv >/dev/null 2>&1; then
  UV=(uv)
elif [[ -x "$HOME/.local/bin/uv" ]]; then
  UV=("$HOME/.local/bin/uv")
else
  echo "check-fixtures: error: uv is not installed; run 'npm run setup' (or: python3 -m pip install --user 'uv==$want_uv')." >&2
  exit 2
fi
have_uv="$("${UV[@]}" --version 2>/dev/null | awk '{print $2}')"
if [[ "$have_uv" != "$want_uv" ]]; then
  echo "check-fixtures: warning: uv $have_uv found, tests/reference/UV_VERSION pins $want_uv." >&2
fi

TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

# The last bits of NumPy/SciPy results depend on the OpenBLAS kernels chosen for the CPU: on a
# machine with AVX-512 OpenBLAS picks its SkylakeX kernels, whose sums round differently from the
# AVX2 (Haswell) ones the fixtures were made with (body_rig.json differed in the 16th digit).
# So the generators run with the Haswell kernels (any x86-64 machine from 2013 on has them) and
# one BLAS thread, which makes the bytes the same on every such machine.
BLAS_ENV=(OPENBLAS_NUM_THREADS=1)
if [[ "$(uname -m)" == "x86_64" ]]; then
  BLAS_ENV+=(OPENBLAS_CORETYPE=Haswell)
fi

# --frozen: use uv.lock as committed (fail rather than re-resolve).
run_py() {
  env "${BLAS_ENV[@]}" PYTHONDONTWRITEBYTECODE=1 UV_PYTHON_DOWNLOADS=never "${UV[@]}" run --frozen --quiet --project "$PROJECT" --python python3.11 python "$@"
}
if ! run_py -c "import numpy, scipy, sklearn" 2>"$TMP/setup.log"; then
  cat "$TMP/setup.log" >&2
  echo "check-fixtures: error: cannot set up the reference environment (tests/reference); see above." >&2
  exit 2
fi

status=0
for entry in "${GENERATORS[@]}"; do
  script="${entry%%:*}"
  outputs="${entry#*:}"
  dir="$(dirname "$ROOT/$script")"
  out="$TMP/$(basename "$script" .py)"
  mkdir -p "$out"
  if ! (cd "$ROOT" && run_py "$script" --out "$out"); then
    echo "check-fixtures: FAIL: $script exited with an error." >&2
    status=1
    continue
  fi
  IFS=',' read -r -a files <<<"$outputs"
  for f in "${files[@]}"; do
    committed="$dir/$f"
    if [[ ! -f "$committed" ]]; then
      echo "check-fixtures: FAIL: ${committed#"$ROOT"/} is missing (run $script to create it)." >&2
      status=1
    elif cmp -s "$out/$f" "$committed"; then
      echo "check-fixtures: ok   ${committed#"$ROOT"/} ($(wc -c <"$committed") bytes) is what $script produces"
    else
      echo "check-fixtures: FAIL: ${committed#"$ROOT"/} differs from what $script produces now:" >&2
      diff <(tr ',' '\n' <"$committed") <(tr ',' '\n' <"$out/$f") | head -20 >&2 || true
      echo "check-fixtures: regenerate with: ${BLAS_ENV[*]} UV_PYTHON_DOWNLOADS=never uv run --project tests/reference --python python3.11 python $script" >&2
      echo "check-fixtures: (and review why the numbers changed before committing)" >&2
      status=1
    fi
  done
done

if [[ $status == 0 ]]; then
  echo "check-fixtures: all fixtures reproduce byte for byte"
fi
exit $status

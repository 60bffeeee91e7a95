#!/usr/bin/env bash
# Installs everything MOSAIC needs on a fresh Debian machine with Node 20, Rust (rustup) and
# Python 3.11, then builds it. Idempotent and quick when everything is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

WASM_BINDGEN_VERSION=0.2.130   # must equal the wasm-bindgen crate pinned in core-wasm/bindings
say() { printf '\033[1msetup:\033[0m %s\n' "$*"; }

# 1. Debian packages used by the test suite and the tools: Chromium (UI tests), socat (serial ptys).
need_apt=()
command -v chromium >/dev/null 2>&1 || need_apt+=(chromium)
command -v socat >/dev/null 2>&1 || need_apt+=(socat)
if [ ${#need_apt[@]} -gt 0 ]; then
  say "installing Debian packages: ${need_apt[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
fi

# 2. npm packages (exact versions from package-lock.json).
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  say "installing npm packages"
  # The Electron binary cannot be downloaded on build machines; the desktop app is packaged elsewhere.
  ELECTRON_SKIP_BINARY_DOWNLOAD=1 npm ci --no-fund --no-audit
fi

# 3. Rust: the wasm32 target and the pinned wasm-bindgen CLI (~4 minutes the first time).
if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
  say "adding the wasm32-unknown-unknown Rust target"
  rustup target add wasm32-unknown-unknown
fi
if ! wasm-bindgen --version 2>/dev/null | grep -q " ${WASM_BINDGEN_VERSION}\$"; then
  say "installing wasm-bindgen-cli ${WASM_BINDGEN_VERSION} (takes a few minutes once)"
  cargo install wasm-bindgen-cli --version "${WASM_BINDGEN_VERSION}"
fi

# 4. Python: uv (from PyPI) and the reference environment (numpy, scipy, scikit-learn) used to
#    regenerate test fixtures. Never downloads a Python interpreter.
export UV_PYTHON_DOWNLOADS=never
UV_VERSION=$(cat tests/reference/UV_VERSION)
if ! python3 -m uv --version 2>/dev/null | grep -q " ${UV_VERSION}"; then
  say "installing uv ${UV_VERSION}"
  pip_install() { python3 -m pip install --quiet --user --disable-pip-version-check "$@" "uv==${UV_VERSION}"; }
  if ! python3 -m pip --version >/dev/null 2>&1; then
    # Debian's own python3 comes without pip.
    SUDO=""
    [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get install -y -qq --no-install-recommends python3-pip >/dev/null
  fi
  # A Debian-managed python3 refuses user installs unless told that uv may live beside it (PEP 668).
  pip_install 2>/dev/null || pip_install --break-system-packages
fi
python3 -m uv sync --quiet --project tests/reference --python python3.11 --frozen
python3 -m uv sync --quiet --project native-bridges/python --python python3.11 --frozen

# 5. Build the WASM core and the bundles.
bash scripts/build.sh

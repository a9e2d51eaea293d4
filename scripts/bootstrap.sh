#!/usr/bin/env bash
# Create .venv with a Python >= 3.12 and install fenics-drill into it (idempotent).
# Interpreter search: $PYTHON if set, else python3.13 / python3.12 / python3 that
# actually run and are >= 3.12, else pyenv's installed 3.12+/3.13+ versions.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=.venv
STAMP="$VENV/.installed"

good() { # prints the interpreter path if it runs and is >= 3.12
  "$1" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 12) else 1)' >/dev/null 2>&1 && echo "$1"
}

find_python() {
  if [ -n "${PYTHON:-}" ]; then
    good "$PYTHON" || { echo "bootstrap: \$PYTHON=$PYTHON does not run or is older than 3.12" >&2; exit 1; }
    return
  fi
  for cand in python3.13 python3.12 python3; do
    if command -v "$cand" >/dev/null 2>&1 && good "$cand"; then return; fi
  done
  for root in "${PYENV_ROOT:-$HOME/.pyenv}/versions" /usr/local/bin; do
    for cand in "$root"/3.13*/bin/python3 "$root"/3.12*/bin/python3; do
      [ -x "$cand" ] && good "$cand" && return
    done
  done
  echo "bootstrap: no Python >= 3.12 found. Install one (e.g. 'pyenv install 3.12') or set PYTHON=/path/to/python3.12" >&2
  exit 1
}

if [ ! -x "$VENV/bin/python" ] || ! good "$VENV/bin/python" >/dev/null; then
  PY=$(find_python)
  echo "bootstrap: creating $VENV with $PY ($("$PY" --version 2>&1))"
  rm -rf "$VENV"
  "$PY" -m venv "$VENV"
fi
if [ ! -f "$STAMP" ] || [ pyproject.toml -nt "$STAMP" ]; then
  "$VENV/bin/python" -m pip install --quiet --upgrade pip
  "$VENV/bin/python" -m pip install --quiet -e ".[test,docs]"
  touch "$STAMP"
fi

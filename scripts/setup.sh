#!/usr/bin/env bash
# Sets up a fresh machine for lookdev: Debian's libllvm19 (for Mitsuba's fast LLVM
# variant, where apt is available), a virtual environment in .venv, and the package with
# its test extras. Safe to run again: it only does what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! ldconfig -p 2>/dev/null | grep -q 'libLLVM.so.19'; then
  if command -v apt-get >/dev/null 2>&1; then
    SUDO=""
    [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null 2>&1 && SUDO="sudo"
    echo "setup: installing libllvm19 for Mitsuba's LLVM variant"
    if ! { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libllvm19; } >/tmp/lookdev-apt.log 2>&1; then
      echo "setup: warning: could not install libllvm19 (see /tmp/lookdev-apt.log); renders fall back to scalar_rgb" >&2
    fi
  else
    echo "setup: warning: apt-get not available; renders fall back to Mitsuba's scalar_rgb variant" >&2
  fi
fi

# Headless Chromium opens the proof review page in tests/pipeline/analysis/test_review.py.
if ! command -v chromium >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null 2>&1 && SUDO="sudo"
  echo "setup: installing chromium for the review-page test"
  if ! { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium; } >/tmp/lookdev-apt-chromium.log 2>&1; then
    echo "setup: warning: could not install chromium (see /tmp/lookdev-apt-chromium.log); the review-page browser test will be skipped" >&2
  fi
fi

PYTHON=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$PYTHON" -m venv .venv
fi
stamp=.venv/.lookdev-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  echo "setup: installing lookdev and its dependencies into .venv (log: .venv/pip.log)"
  if ! { .venv/bin/python -m pip install -q --upgrade pip &&
         .venv/bin/python -m pip install -q -e '.[test]'; } >.venv/pip.log 2>&1; then
    tail -n 30 .venv/pip.log >&2
    echo "setup: error: pip install failed (full log: .venv/pip.log)" >&2
    exit 1
  fi
  touch "$stamp"
fi

# The documentation site's tools (the `docs` extra: Sphinx, MyST, numpydoc, bibtex), which
# scripts/test.sh uses to build docs/ with warnings as errors.
docs_stamp=.venv/.lookdev-docs-installed
if [ ! -f "$docs_stamp" ] || [ pyproject.toml -nt "$docs_stamp" ]; then
  echo "setup: installing the documentation tools into .venv (log: .venv/pip-docs.log)"
  if ! .venv/bin/python -m pip install -q -e '.[docs]' >.venv/pip-docs.log 2>&1; then
    tail -n 30 .venv/pip-docs.log >&2
    echo "setup: error: pip install of the docs extra failed (full log: .venv/pip-docs.log)" >&2
    exit 1
  fi
  touch "$docs_stamp"
fi

# Blender as a test consumer (tests marked dcc): the bpy wheel pins its own Python
# (3.11 for bpy 4.5), so it gets a venv of its own, .venv-blender. Set
# LOOKDEV_BLENDER_PYTHON to use another interpreter that imports bpy.
if [ -z "${LOOKDEV_BLENDER_PYTHON:-}" ] && [ ! -f .venv-blender/.lookdev-installed ]; then
  BLENDER_PYTHON=${BLENDER_PYTHON:-python3.11}
  if command -v "$BLENDER_PYTHON" >/dev/null 2>&1; then
    echo "setup: installing Blender (bpy 4.5) into .venv-blender (log: .venv-blender/pip.log)"
    "$BLENDER_PYTHON" -m venv .venv-blender
    if .venv-blender/bin/python -m pip install -q 'bpy==4.5.*' >.venv-blender/pip.log 2>&1; then
      touch .venv-blender/.lookdev-installed
    else
      echo "setup: warning: bpy did not install (see .venv-blender/pip.log); the dcc tests will be skipped" >&2
    fi
  else
    echo "setup: warning: no $BLENDER_PYTHON for Blender's bpy; the dcc tests will be skipped" >&2
  fi
fi

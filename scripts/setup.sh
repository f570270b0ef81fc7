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
# pip byte-compiles what it installs, but an editable install leaves lookdev's own source
# to be compiled by every command that imports it (and never cached where
# PYTHONDONTWRITEBYTECODE is set): ≈ 0.04 CPU s a command line. Python re-checks each
# .pyc against its source's mtime, so an edited file is never run stale.
.venv/bin/python -m compileall -q -j 0 materials library pipeline >/dev/null || true

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
# (3.11 for bpy 4.5 and for bpy 5.0), so each Blender gets a venv of its own:
# .venv-blender (bpy 4.5, the LTS) and .venv-blender5 (the newest bpy, 5.x); the dcc
# tests run against each one installed. Set LOOKDEV_BLENDER_PYTHON to use only another
# interpreter that imports bpy.
install_blender() {  # venv, pip requirement
  local venv=$1 want=$2
  [ -f "$venv/.lookdev-installed" ] && return 0
  local python=${BLENDER_PYTHON:-python3.11}
  if ! command -v "$python" >/dev/null 2>&1; then
    echo "setup: warning: no $python for Blender's bpy ($want); the dcc tests will skip it" >&2
    return 0
  fi
  echo "setup: installing Blender ($want) into $venv (log: $venv/pip.log)"
  "$python" -m venv "$venv"
  if "$venv/bin/python" -m pip install -q "$want" >"$venv/pip.log" 2>&1; then
    touch "$venv/.lookdev-installed"
  else
    # No venv without its bpy: the dcc tests run against every venv that exists.
    mv "$venv/pip.log" "$venv-pip.log"
    rm -rf "$venv"
    echo "setup: warning: $want did not install (see $venv-pip.log); the dcc tests will skip it" >&2
  fi
}
if [ -z "${LOOKDEV_BLENDER_PYTHON:-}" ]; then
  install_blender .venv-blender 'bpy==4.5.*'
  install_blender .venv-blender5 'bpy==5.*'
fi

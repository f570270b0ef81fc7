#!/usr/bin/env bash
# The README's test command: set up, lint, run the test suite and the stability report.
# Every step runs even when an earlier one fails (a red test must not hide the stability
# report); the exit status is non-zero if any step failed.
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh || exit 1
export PATH="$PWD/.venv/bin:$PATH"

failed=()
step() {
  echo "== $*"
  "$@" || failed+=("$*")
}

step ruff check .
step ruff format --check .
step python -m pytest -n 2 -q "$@"
# The doctests once more under a second OpenBLAS kernel: OpenBLAS picks its kernel by
# processor, so a float computed through BLAS/LAPACK differs in its last bits from one
# machine to the next, and no example may print such a float unrounded.
if [ "$(uname -m)" = x86_64 ]; then
  OPENBLAS_CORETYPE=Prescott step python -m pytest -q -p no:cacheprovider materials library pipeline
fi
step lookdev check
# The documentation site from docs/ (MyST pages, the API reference from the docstrings, the
# bibliography), warnings as errors: open docs/_build/html/index.html.
step python -m sphinx -W --keep-going -q -b html docs docs/_build/html

if [ ${#failed[@]} -gt 0 ]; then
  printf 'test.sh: failed: %s\n' "${failed[@]}" >&2
  exit 1
fi

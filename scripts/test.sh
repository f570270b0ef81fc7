#!/usr/bin/env bash
# The README's test command: set up, lint, run the test suite and the stability report.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
ruff check .
ruff format --check .
python -m pytest -n 2 -q "$@"
lookdev check

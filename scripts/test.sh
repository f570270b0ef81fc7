#!/usr/bin/env bash
# The README's test command: set up, lint, run the test suite and the stability report,
# then build the documentation site.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
ruff check .
ruff format --check .
python -m pytest -n 2 -q "$@"
lookdev check

# The documentation site from docs/ (MyST pages, the API reference from the docstrings, the
# bibliography), warnings as errors: open docs/_build/html/index.html.
python -m sphinx -W --keep-going -q -b html docs docs/_build/html

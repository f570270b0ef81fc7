#!/usr/bin/env bash
# The README's main command: set up, then run the main job on built-in defaults.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
lookdev --version

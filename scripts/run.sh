#!/usr/bin/env bash
# The README's main command: set up, then the main job on built-in defaults:
# turntable proofs of a representative set of built-in presets under every built-in IBL,
# then a USD export of the presets that were proofed. Re-running resumes: frames already
# rendered (verified by their manifest entries) are skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
lookdev --version

OUT="${LOOKDEV_PROOFS:-proofs}"
lookdev proof -o "$OUT" --report "$@"

# The presets the batch proofed, from its manifest, exported as one USD library.
mapfile -t PRESETS < <(python - "$OUT/manifest.json" <<'PY'
import json, sys
print("\n".join(sorted({p["material"] for p in json.load(open(sys.argv[1]))["proofs"]})))
PY
)
lookdev export usd "${PRESETS[@]}" -o "$OUT/proofed.usda"
echo "review page: $OUT/index.html; proofs: $OUT/*/*/contact.png; USD: $OUT/proofed.usda"

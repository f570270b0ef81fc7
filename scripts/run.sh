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

# The example asset: a pebble mesh over four UDIM tiles and its painted texture set,
# generated (no downloads), proofed on its own mesh, exported as a self-contained asset.
ASSET="$OUT/asset"
python scripts/make_example_asset.py "$ASSET/source"
lookdev proof "$ASSET/source/pebble.toml" --geometry "$ASSET/source/pebble.obj" \
    --ibl studio --frames 4 --light-frames 4 -o "$ASSET"
lookdev export usd "$ASSET/source/pebble.toml" -o "$ASSET/pebble.usda" --collect --preview-geometry \
    --map-resolution 256
echo "review page: $OUT/index.html; proofs: $OUT/*/*/contact.png; USD: $OUT/proofed.usda"
echo "example asset: $ASSET/pebble/studio/contact.png; USD: $ASSET/pebble.usda"

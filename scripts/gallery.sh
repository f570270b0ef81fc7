#!/usr/bin/env bash
# The README's gallery: one proof frame of each subsurface preset and of the model
# features that only a render shows, under the studio IBL, denoised, copied to
# docs/gallery/ as PNG (through the OCIO view). Re-run after a change to a model or a
# preset and commit the images with it; it takes a few minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/.venv/bin:$PATH"
OUT="${LOOKDEV_GALLERY_RENDERS:-$(mktemp -d)}"
PRESETS=(skin marble milk ketchup jade porcelain snow velvet glass_clear gold)
lookdev proof "${PRESETS[@]}" --ibl studio --frames 1 --light-frames 0 \
    --spp 64 --denoise --rig none -r 480 240 -o "$OUT"
mkdir -p docs/gallery
for p in "${PRESETS[@]}"; do
    cp "$OUT/$p/studio/frame_000_denoised.png" "docs/gallery/$p.png"
done
echo "gallery: docs/gallery/*.png (renders in $OUT)"

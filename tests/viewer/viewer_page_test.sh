#!/usr/bin/env bash
# ctest viewer.page_in_chromium: a small reconstruction's scene.glb (glint synth cubes + glint
# reconstruct), `glint view OUT --write-html SITE`, and web/tests/render-viewer.mjs, which serves
# SITE on 127.0.0.1 and loads it in headless Chromium. Fails on any console error or failed
# request, an empty canvas, or a scene without its lights and segments.
# Exit 77 (skipped, with the reason) without node, web/node_modules or Chromium.
#   tests/viewer/viewer_page_test.sh GLINT SOURCE_DIR WORK
set -euo pipefail
glint=$1 source_dir=$2 work=$3
command -v node >/dev/null || { echo "skipped: node not found"; exit 77; }
[[ -d "$source_dir/web/node_modules/puppeteer-core" ]] ||
  { echo "skipped: web/node_modules missing (scripts/install-deps.sh runs npm ci)"; exit 77; }
[[ -x /usr/bin/chromium ]] || { echo "skipped: /usr/bin/chromium missing (apt-get install chromium)"; exit 77; }
rm -rf "$work"
mkdir -p "$work"
trap 'rm -rf "$work"' EXIT
"$glint" --quiet synth cubes --frames 8 --width 128 --no-shadows -o "$work/seq"
"$glint" --quiet reconstruct "$work/seq" --gt-lights --gt-poses --gt-segmentation --obs-spacing 0 \
  --mesh-triangles 5000 --texture-size 512 -o "$work/out"
"$glint" --quiet view "$work/out" --write-html "$work/site"
# A magenta background: the model counts as drawn even where it is dark.
result=$(node "$source_dir/web/tests/render-viewer.mjs" --dir "$work/site" --check --background ff00ff \
  --out "$work/shot.png")
echo "$result"
node -e '
  const r = JSON.parse(process.argv[1]);
  if (!(r.lights > 0 && r.segments > 1 && r.triangles > 100)) {
    console.error(`expected lights, segments and triangles in the page: ${process.argv[1]}`);
    process.exit(1);
  }' "$result"

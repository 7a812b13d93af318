#!/usr/bin/env bash
# Regenerates tests/fixtures/oracle/*.json with the independent slicing oracle
# (../shared/tools/oracle_sections.py; needs numpy and shapely, see its README).
# Layer height 0.2 mm, planes at mid-layer (the default slice_plane = middle).
set -euo pipefail
cd "$(dirname "$0")/.."
shared=${DROPSLICE_SHARED:-../shared}
out=tests/fixtures/oracle
mkdir -p "$out"
for m in cube_20mm_ascii 3DBenchy extruder_idler spikey_top_solid_header \
         slide_n_snap_test_a_medium airfoil_wing M3x10_screw esca_nonmanifold; do
  python3 "$shared/tools/oracle_sections.py" "$shared/models/$m.stl" 0.2 > "$out/$m.json"
  echo "$m done" >&2
done
# the open scan: chains joined end-to-start as CuraEngine and Slic3r do
python3 "$shared/tools/oracle_sections.py" "$shared/models/stanford_bunny.stl" 0.2 --close-open 1e9 \
  > "$out/stanford_bunny_close_open.json"
echo "stanford_bunny done" >&2
# the same scan with its holes filled by MeshFix: the reference its closed sections are held to
# (needs numpy and pymeshfix, see scripts/fill_holes_meshfix.py)
filled=$(mktemp --suffix=.stl)
python3 scripts/fill_holes_meshfix.py "$shared/models/stanford_bunny.stl" "$filled"
python3 "$shared/tools/oracle_sections.py" "$filled" 0.2 > "$out/stanford_bunny_holes_filled.json"
rm -f "$filled"
echo "stanford_bunny (holes filled) done" >&2

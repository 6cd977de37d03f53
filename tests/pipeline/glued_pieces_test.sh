#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# glued_pieces_test.sh ZOMEFAB DATA_DIR OUTDIR: pieces the maker would glue together anyway are
# printed as one where they fit the printer (docs/mounting.md, "Glued pairs printed as one"). The dino
# at 500 mm had two toes (3 and 5 cm³, no peg can reach them) glued to a leg that was glued to the
# body: 12 pieces. Now the toes are printed with the leg: no piece under 10 cm³ is left in a glued
# group or glued on, the run's summary counts the merges, and the verifier passed (exit 0).
set -u
zf=$1 data=$2 out=$3
rm -rf "$out" "$out.failed"
"$zf" run "$data/dino_cgal_8k.stl" --up z --height-mm 500 -o "$out" -q 2>"$out.err" ||
  { echo "zomefab run failed: $(cat "$out.err")"; exit 1; }
python3 - "$out/pieces/pieces.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
pieces, inst = j["pieces"], j["installation"]
glued = {p for s in inst["steps"] if len(s["pieces"]) > 1 for p in s["pieces"]}
glued |= {p for pair in inst.get("glued_on", []) for p in pair}
small = [p["piece"] for p in pieces if p["piece"] in glued and p["shell_volume_mm3"] < 10000]
print(f"{len(pieces)} pieces, {j['summary']['merged_pieces']} merged, glued: {sorted(glued)}, "
      f"glued under 10 cm³: {small}")
ok = not small and j["summary"]["merged_pieces"] >= 2
sys.exit(0 if ok else 1)
PY

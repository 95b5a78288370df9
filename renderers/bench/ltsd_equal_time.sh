#!/usr/bin/env bash
# Equal-time error of LTSD and Volume-RIS against the reference: issue 18's table (the LTSD paper's Fig. 2, 7 and 10).
#   renderers/bench/ltsd_equal_time.sh [build folder] [output folder]
# For each bundled scene: the reference at 4096 spp; LTSD at N = 1, 8 and 64 nodes (its render time measured); and
# Volume-RIS (8 candidates) given exactly that time (--time). Each image's relMSE against the reference comes from
# `tyndall compare`. LTSD's time includes its ratio-estimated shadows (16 samples, denoised) when the view has them.
# Writes <output>/table.md (docs/ltsd.md, "Equal time").
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build}
out=${2:-/tmp/ltsd-equal-time}
tyndall="$build/studio/cli/tyndall"
mkdir -p "$out"

seconds_of() {  # the render time "(W x H, S spp, T s)" that `tyndall render` prints
    sed -n 's/.*spp, \([0-9.e+-]*\) s).*/\1/p' | tail -n 1
}
relmse_of() {  # image reference
    "$tyndall" compare "$1" -r "$2" --json "$out/compare.json" >/dev/null
    python3 -c "import json,sys; m=json.load(open(sys.argv[1]))['images'][0]; print('%.3g' % m['relMSE'])" "$out/compare.json"
}

{
    echo "| scene | N | LTSD time | LTSD relMSE | Volume-RIS relMSE at that time |"
    echo "|---|---|---|---|---|"
} >"$out/table.md"
# scene file, the LTSD view whose part the reference renders, the Volume-RIS view
for entry in "ltsd/fig10-nodes.json|N 8 equiangular|volume-ris" "ltsd/shaft.json|ltsd|volume-ris"; do
    IFS='|' read -r scene ltsd ris <<<"$entry"
    project="$root/projects/$scene"
    name=$(basename "$scene" .json)
    "$tyndall" render "$project" --view "$ltsd" --reference --spp 4096 -o "$out/$name-reference.exr" >/dev/null
    for n in 1 8 64; do
        time=$("$tyndall" render "$project" --view "$ltsd" --set "views[$ltsd].parameters.nodes=$n" \
                   -o "$out/$name-ltsd-$n.exr" | seconds_of)
        "$tyndall" render "$project" --view "$ris" --time "$time" -o "$out/$name-ris-$n.exr" >/dev/null
        echo "| $name | $n | $time s | $(relmse_of "$out/$name-ltsd-$n.exr" "$out/$name-reference.exr") |" \
             "$(relmse_of "$out/$name-ris-$n.exr" "$out/$name-reference.exr") |" >>"$out/table.md"
    done
done
cat "$out/table.md"

#!/bin/sh
# Checks that a change leaves every image bitwise the same: renders every Tachyon example scene
# (Debian's tachyon-doc; 256x256, 2 threads, and 200x200 on 1 thread for three of them), the SPD
# scenes in ../shared/spd (256x256) and the repository's still scenes (128x96), each to EXR, and
# prints the MD5 of each (also written to OUTDIR/SUMS). Make the reference with main's build, then
# compare:
#
#   sh examples/image_sums.sh target/release/luxon /tmp/sums-main    # on main
#   sh examples/image_sums.sh target/release/luxon /tmp/sums-new     # on the change
#   diff /tmp/sums-main/SUMS /tmp/sums-new/SUMS                      # empty: bitwise the same
#
# About 15 s on 2 cores. A line "FAIL name" is a render that failed (its stderr: OUTDIR/name.err).
set -u
[ $# -eq 2 ] || { echo "usage: $0 LUXON OUTDIR" >&2; exit 2; }
repo=$(cd "$(dirname "$0")/.." && pwd)
luxon=$(readlink -f "$1")
out=$(readlink -f -m "$2")
mkdir -p "$out"
scenes=/usr/share/doc/tachyon/examples/scenes
if [ -d "$scenes" ]; then
    # A copy: some scenes name their image maps and volumes relative to the working directory.
    copy=$(mktemp -d)
    cp -r "$scenes"/. "$copy"
    cd "$copy" || exit 1
    for s in *.dat; do
        n=${s%.dat}
        case $n in dnadof | sc98ao | texture) continue ;; esac # minutes each; Tachyon rejects texture
        "$luxon" render "$s" --res 256x256 --threads 2 -o "$out/t-$n.exr" >/dev/null 2>"$out/t-$n.err" ||
            echo "FAIL t-$n"
    done
    for n in fog 820spheres balls; do
        "$luxon" render "$n.dat" --res 200x200 --threads 1 -o "$out/t1-$n.exr" >/dev/null 2>"$out/t1-$n.err" ||
            echo "FAIL t1-$n"
    done
    cd "$repo" && rm -rf "$copy"
else
    echo "note: $scenes not found (apt-get install tachyon-doc): Tachyon's scenes skipped" >&2
fi
for f in "$repo"/../shared/spd/*.nff.gz; do
    [ -e "$f" ] || continue
    n=$(basename "$f" .nff.gz)
    zcat "$f" >"$out/$n.nff"
    "$luxon" render "$out/$n.nff" --res 256x256 --threads 2 --no-cache -o "$out/s-$n.exr" >/dev/null \
        2>"$out/s-$n.err" || echo "FAIL s-$n"
    rm -f "$out/$n.nff"
done
cd "$repo/scenes" || exit 1
for s in *.ron; do
    n=${s%.ron}
    # Animated scenes (their frames) and the OpenVDB cloud (needs the vdb plugin's library) are
    # left out.
    case $n in carousel | shared-instances | orbit | bouncing-ball | gears | vdb-cloud) continue ;; esac
    "$luxon" render "$s" --res 128x96 --threads 2 -o "$out/r-$n.exr" >/dev/null 2>"$out/r-$n.err" ||
        echo "FAIL r-$n"
done
cd "$out" && md5sum ./*.exr | sed 's| \./| |' | tee SUMS

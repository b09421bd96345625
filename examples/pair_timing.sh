#!/usr/bin/env bash
# A/B timing of two Luxon builds on a noisy 2-core machine: both render the same scene at the
# same time, one pinned to each core (swapping cores every round), so both see the same load;
# prints the median over rounds of B's render time divided by A's. A build against itself
# gave 1.00 and 1.02 (12 and 14 rounds): differences under 2 % need more rounds than that.
# Needs `taskset` (util-linux) and two CPUs.
#
#   examples/pair_timing.sh DIR_A DIR_B SCENE [ROUNDS]
#
# DIR_A and DIR_B each hold a `luxon` binary (and the plugins it loads, e.g. copies of
# target/release/). Renders use one thread each, no geometry cache, and `--stats`' render time.
set -euo pipefail
if [ $# -lt 3 ]; then
    sed -n '2,11p' "$0" >&2
    exit 2
fi
a=$1 b=$2 scene=$3 rounds=${4:-20}
for d in "$a" "$b"; do
    [ -x "$d/luxon" ] || { echo "pair_timing: no executable $d/luxon" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
render_time() { awk '/^  render /{print $2}' "$1"; }
for r in $(seq "$rounds"); do
    if [ $((r % 2)) = 0 ]; then ca=0 cb=1; else ca=1 cb=0; fi
    taskset -c $ca "$a/luxon" render "$scene" -o "$work/a.png" --no-cache --threads 1 --stats \
        >"$work/a.txt" 2>&1 &
    taskset -c $cb "$b/luxon" render "$scene" -o "$work/b.png" --no-cache --threads 1 --stats \
        >"$work/b.txt" 2>&1 &
    wait
    ta=$(render_time "$work/a.txt") tb=$(render_time "$work/b.txt")
    if [ -z "$ta" ] || [ -z "$tb" ]; then
        echo "pair_timing: round $r: a render failed:" >&2
        cat "$work/a.txt" "$work/b.txt" >&2
        exit 1
    fi
    echo "$ta $tb" >>"$work/times"
    echo "round $r: A $ta s, B $tb s" >&2
done
sort_median() { sort -g | awk '{v[NR]=$1} END {print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }
ratio=$(awk '{print $2/$1}' "$work/times" | sort_median)
ma=$(awk '{print $1}' "$work/times" | sort_median)
mb=$(awk '{print $2}' "$work/times" | sort_median)
faster=$(awk '$2 < $1' "$work/times" | wc -l)
echo "B/A render time: median ratio $ratio over $rounds rounds (A median $ma s, B median $mb s; B faster in $faster)"

#!/bin/sh
# Frame throughput of a 48-frame sequence (scenes/carousel.ron, RES, default 320x240, one thread
# per rank) at 1 and 2 MPI ranks, for each way the ranks share the frames: whole frames per rank,
# groups of 2 ranks sharing each frame, every rank on every frame. Prints Markdown tables of the
# medians of RUNS runs (default 3) and efficiency = t1 / (2 t2), of two times:
#   wall:   the whole command (mpirun, MPI start-up, scene, frames, exit);
#   frames: from the first rank ready to the last rank done (the frames alone, start-up and exit
#           left out), from the time lines `--stats` prints for each rank.
#
# The same run measures what the machine itself allows: one plain process (no MPI, one thread)
# rendering the 48 frames alone, then two such processes side by side (each its own outputs);
# ceiling = t_alone / t_pair, the efficiency two independent jobs reach. The last column is the
# MPI efficiency relative to that ceiling.
#
# Needs a release build with MPI: cargo build --release --features mpi. Run from the
# repository's root.
set -eu
runs=${RUNS:-3}
res=${RES:-320x240}
luxon=${LUXON:-target/release/luxon}
out=${OUT:-/tmp/luxon-frames-bench}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# "wall frames" seconds of running the command, whose `--stats` go to $out/log*.
timed() {
    rm -rf "$out"
    mkdir -p "$out"
    t0=$(date +%s.%N)
    "$@"
    t1=$(date +%s.%N)
    cat "$out"/log* | awk -v wall="$t0 $t1" '
        / of [0-9]+: ready after / {
            for (i = 1; i <= NF; i++) {
                if ($i == "ready") r = $(i + 2)
                if ($i == "done") d = $(i + 2)
            }
            if (n == 0 || r < ready) ready = r
            if (n == 0 || d > done) done = d
            n++
        }
        END { split(wall, w, " "); printf "%.3f %.3f\n", w[2] - w[1], done - ready }'
}

# One plain render of the 48 frames into $out/$1.
plain() {
    "$luxon" render scenes/carousel.ron --frames 0..47 --threads 1 --res "$res" --force \
        --stats -o "$out/$1/f%04d.png" 2>"$out/log-$1"
}

# Two plain renders side by side; returns when both are done.
pair() {
    plain a &
    a=$!
    plain b &
    b=$!
    wait "$a"
    wait "$b"
}

# mpirun -np $1 ... --frame-groups $2.
ranks() {
    mpirun --oversubscribe -np "$1" --bind-to none "$luxon" render scenes/carousel.ron \
        --frames 0..47 --threads 1 --res "$res" --force --frame-groups "$2" --stats \
        -o "$out/f%04d.png" 2>"$out/log"
}

# The median of column $1 of $out.runs.
column() {
    cut -d' ' -f"$1" "$out.runs" | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}

# Medians of RUNS runs of the command: "wall frames".
median() {
    i=0
    while [ $i -lt "$runs" ]; do
        timed "$@"
        i=$((i + 1))
    done >"$out.runs"
    echo "$(column 1) $(column 2)"
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
alone=$(median plain x)
both=$(median pair)
ceiling=$(echo "$alone $both" | awk '{ printf "%.1f %.1f", 100 * $1 / $3, 100 * $2 / $4 }')
echo "$alone $both $ceiling" | awk -v res="$res" '{
    printf "ceiling at %s: one process alone %.2f s (frames %.2f s), two side by side %.2f s (frames %.2f s): %.1f %% (frames %.1f %%)\n",
        res, $1, $2, $3, $4, $5, $6 }'
t1=$(median ranks 1 whole)
echo "| frames shared by | time | 1 rank s | 2 ranks s | frames/s at 2 ranks | efficiency | of the ceiling |"
echo "|---|---|---:|---:|---:|---:|---:|"
for groups in whole 2 shared; do
    t2=$(median ranks 2 "$groups")
    echo "$groups $t1 $t2 $ceiling" | awk '{
        for (j = 0; j < 2; j++) {
            e = 100 * $(2 + j) / (2 * $(4 + j))
            printf "| `--frame-groups %s` | %s | %.2f | %.2f | %.2f | %.1f %% | %.1f %% |\n",
                $1, j ? "frames" : "wall", $(2 + j), $(4 + j), 48 / $(4 + j), e, 100 * e / $(6 + j)
        } }'
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
rm -rf "$out" "$out.runs"

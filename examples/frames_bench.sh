#!/bin/sh
# Frame throughput of a 48-frame sequence (scenes/carousel.ron, 320x240, one thread per rank) at
# 1 and 2 MPI ranks, for each way the ranks share the frames: whole frames per rank, groups of
# 2 ranks sharing each frame, every rank on every frame. Prints a Markdown table of the median
# wall times of RUNS runs (default 3) and efficiency = t1 / (2 t2). Needs a release build with
# MPI: cargo build --release --features mpi. Run from the repository's root.
set -eu
runs=${RUNS:-3}
luxon=${LUXON:-target/release/luxon}
out=${OUT:-/tmp/luxon-frames-bench}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Wall seconds of one run: mpirun -np $1 ... --frame-groups $2.
once() {
    rm -rf "$out"
    t0=$(date +%s.%N)
    mpirun --oversubscribe -np "$1" --bind-to none "$luxon" render scenes/carousel.ron \
        --frames 0..47 --threads 1 --res "${RES:-320x240}" --force --frame-groups "$2" \
        -o "$out/f%04d.png" 2>/dev/null
    t1=$(date +%s.%N)
    echo "$t0 $t1" | awk '{ printf "%.3f\n", $2 - $1 }'
}

# Median of RUNS runs.
median() {
    i=0
    while [ $i -lt "$runs" ]; do
        once "$1" "$2"
        i=$((i + 1))
    done | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
}

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
t1=$(median 1 whole)
echo "| frames shared by | 1 rank s | 2 ranks s | frames/s at 2 ranks | efficiency |"
echo "|---|---:|---:|---:|---:|"
for groups in whole 2 shared; do
    t2=$(median 2 "$groups")
    echo "$groups $t1 $t2" | awk '{ printf "| `--frame-groups %s` | %.2f | %.2f | %.2f | %.1f %% |\n", $1, $2, $3, 48 / $3, 100 * $2 / (2 * $3) }'
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
rm -rf "$out"

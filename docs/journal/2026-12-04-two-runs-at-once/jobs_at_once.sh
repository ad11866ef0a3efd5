#!/bin/bash
# Job level: 8 real-material preview runs at h = 10 um (DX56 and bulk zinc, 1 mm ball, 4 / 7 / 11 / 22 N) made by
# `snakemake --cores 2` with mpm.threads 2 (one job at a time) and with mpm.threads 1 (two jobs at a time),
# alternating, each pass from empty results. Run alone (nothing else heavy), in a clean checkout:
#   git worktree add /tmp/wt_conc HEAD --detach
#   bash docs/journal/2026-12-04-two-runs-at-once/jobs_at_once.sh /tmp/wt_conc OUTDIR "2:1 1:1 2:2 1:2"
# (each word THREADS:REPEAT). Prints the wall time of each pass; copies the jobs' benchmark files to OUTDIR.
set -e
WT="$1"; OUT="$2"; PASSES="${3:-2:1 1:1 2:2 1:2}"
mkdir -p "$OUT"
cd "$WT"
export PYTHONPATH="$WT/src"
for t in 1 2; do printf 'mpm:\n  threads: %s\n' "$t" > "$OUT/t$t.yaml"; done
T=""
for m in dx56_bl1.34-0.88_r500 zinc_bulk_bl0.32-0.95_r500; do for F in F4 F7 F11 F22; do T="$T results/runs/${m}_${F}_h10.nc"; done; done
clean() { rm -rf results logs benchmarks/runs .snakemake/metadata .snakemake/incomplete; }
clean  # a first run compiles the kernels into this checkout's cache: not timed
snakemake --cores 2 results/runs/zinc_bulk_bl0.32-0.95_r500_F1_h20.nc --configfile config/preview.yaml "$OUT/t2.yaml" \
    > "$OUT/warm.log" 2>&1
for pass in $PASSES; do
  t=${pass%:*}; rep=${pass#*:}
  clean
  s=$(date +%s.%N)
  snakemake --cores 2 $T --configfile config/preview.yaml "$OUT/t$t.yaml" > "$OUT/jobs_t${t}_$rep.log" 2>&1
  e=$(date +%s.%N)
  echo "threads $t repeat $rep: wall $(python -c "print(round($e - $s, 1))") s"
  mkdir -p "$OUT/bench_t${t}_$rep" && cp benchmarks/runs/*.tsv "$OUT/bench_t${t}_$rep/"
done

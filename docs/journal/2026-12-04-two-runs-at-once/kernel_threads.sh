#!/bin/bash
# Steady-state step: one run on 2 threads, one on 1 thread, two 1-thread runs at once (benchmarks/kernel_profile.py),
# twice. Run alone from the repository root:
#   bash docs/journal/2026-12-04-two-runs-at-once/kernel_threads.sh "" 5 200 ref OUTDIR
#   bash docs/journal/2026-12-04-two-runs-at-once/kernel_threads.sh "--scene examples/zinc_coated_steel.yaml" 10 60 zinc OUTDIR
S="$1"; H="$2"; N="$3"; TAG="$4"; OUT="$5"
mkdir -p "$OUT"
for r in 1 2; do
  python benchmarks/kernel_profile.py $S --h-um $H --steps $N --threads 2 --out "$OUT/${TAG}_t2_$r.json" | grep "particle-steps/s"
  python benchmarks/kernel_profile.py $S --h-um $H --steps $N --threads 1 --out "$OUT/${TAG}_t1_$r.json" | grep "particle-steps/s"
  python benchmarks/kernel_profile.py $S --h-um $H --steps $N --threads 1 --out "$OUT/${TAG}_c1a_$r.json" > "$OUT/${TAG}_c1a_$r.log" 2>&1 &
  python benchmarks/kernel_profile.py $S --h-um $H --steps $N --threads 1 --out "$OUT/${TAG}_c1b_$r.json" > "$OUT/${TAG}_c1b_$r.log" 2>&1
  wait
  grep -h "particle-steps/s" "$OUT/${TAG}_c1a_$r.log" "$OUT/${TAG}_c1b_$r.log"
done

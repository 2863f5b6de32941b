#!/bin/bash
# usage: compare.sh BASE_BIN NEW_BIN OUTDIR  -- runs each case with both, compares CSV (cmp) and sidecars/JSON
BASE=$1; NEW=$2; OUT=$3
rm -rf "$OUT"; mkdir -p "$OUT/base" "$OUT/new"
n=0
run_case() {  # name, args...
  local name=$1; shift
  for side in base new; do
    local bin=$BASE; [ $side = new ] && bin=$NEW
    local d="$OUT/$side/$name"; mkdir -p "$d"
    # file outputs
    (cd "$d" && "$bin" "$@" --output "$d/t.csv" > "$d/stdout.txt" 2> "$d/stderr.txt"; echo $? > "$d/rc")
    # --json with no file (rows in the printed document)
    (cd "$d" && "$bin" "$@" --output "" --json > "$d/json.txt" 2>/dev/null; echo $? > "$d/rc_json")
  done
}
C() { run_case "$@"; }
C orbit_default tapping orbit
C orbit_l5 tapping orbit --separation 5
C orbit_phys tapping orbit --units physical --separation 15
C orbit_q5 tapping orbit --quality-factor 5 --separation 0.9 --max-period-multiple 1
C sweep_default tapping sweep --points 20 --quiet
C sweep_both tapping sweep --points 12 --mode both --quiet
C sweep_phys tapping sweep --units physical --points 10 --separation-min 5 --separation-max 20 --quiet
C sweep_param tapping sweep --parameter drive_frequency --parameter-min 0.9 --parameter-max 1.1 --points 10 --quiet
C sweep_param_both tapping sweep --parameter drive_amplitude --parameter-min 0.1 --parameter-max 0.3 --points 8 --mode both --quiet
C hb_default tapping hb
C hb_minus tapping hb --minus-branch --points 50
C hb_phys tapping hb --units physical --points 40
C fm_default tapping fm --quiet
C fm_gap tapping fm --axis min_gap --quiet
C tf_default control tf
C tf_loop_hz control tf --system loop --frequency-unit Hz --points 50
C roots_default control roots
C roots_inf control roots --controller infinite
C margin_default control margin
C margin_compare control margin --compare
C chart_small control chart --x-points 6 --y-points 5 --boundaries-output b.csv --progress false
C chart_delays control chart --x-points 5 --y-points 4 --delays 0.3,0.1,0.2 --boundaries-output b.csv --progress false
C chart_margin control chart --quantity margin --controller single --x-points 4 --y-points 3 --progress false
C simulate_default control simulate --periods 5
C tune_small control tune --coarse-points 4 --max-evaluations 5 --delay-max 0.25 --progress false

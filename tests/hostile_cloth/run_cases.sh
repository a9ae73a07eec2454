#!/usr/bin/env bash
# Runs the issue-48 cloth/garment/body cases with a release binary, as they were reported:
# one thread, a 4 GB address-space limit, 20 s. Usage (from the repository root):
#   tests/hostile_cloth/run_cases.sh [BINARY] [WORK_DIR]
# Prints, per case: exit status, seconds, peak RSS (MB) and the first line of output (the error).
# The generated inputs (10,000 nested <g>, a BVH whose Frame Time is 1e9) go to WORK_DIR.
set -u
bin=${1:-target/release/emilion}
work=${2:-$(mktemp -d)}
mkdir -p "$work"
here=tests/hostile_cloth
bad=tests/data/patterns_bad
data=$(cd "${EMILION_DATA:-../shared/data}" && pwd)
python3 - "$work" <<'PY'
import sys
n = 10000
s = ('<svg xmlns="http://www.w3.org/2000/svg" width="300mm" height="600mm" viewBox="0 0 300 600">\n'
     + '<g>' * n + '<g id="front"><path d="M 0 0 L 300 0 L 300 600 L 0 600 z"/></g>' + '</g>' * n + '\n</svg>\n')
open(sys.argv[1] + '/nested_10000.svg', 'w').write(s)
PY
sed 's/^Frame Time: .*/Frame Time: 1e9/' "$data/motion/cmu_bvh/002_01.bvh" > "$work/frame_time_1e9.bvh"

run() { # name script [--set k=v ...]
  local name=$1; shift
  local t0=$(date +%s.%N)
  local log="$work/$name.log"
  ( ulimit -v 4000000; RAYON_NUM_THREADS=1 timeout 20 /usr/bin/time -f "%M" -o "$work/$name.rss" \
      "$bin" run "$@" ) >"$log" 2>&1
  local rc=$?
  local t1=$(date +%s.%N)
  local rss=$(tail -1 "$work/$name.rss" 2>/dev/null)
  printf '%-24s rc=%-3s %6.1fs %6s MB  %s\n' "$name" "$rc" "$(echo "$t1 - $t0" | bc)" \
    "$(( ${rss:-0} / 1024 ))" "$(grep -v '^\s*$' "$log" | head -1 | cut -c1-170)"
}
for c in sim_run_1e9 sim_run_1e300 run_steps_int_max dt_tiny dt_huge run_callback_1e9 \
         explicit_substeps_1e9 run_frames_fps_tiny release_out_of_range cloth_grid_1e6 \
         cloth_cone_1e5 cloth_patch_1000m; do
  run "$c" "$here/$c.rhai"
done
run svg_nested "$here/svg_pattern.rhai" --set input="$work/nested_10000.svg"
run svg_viewbox_zero "$here/svg_pattern.rhai" --set input="$PWD/$bad/viewbox_zero.svg"
run piece_100m "$here/pattern_piece.rhai" --set input="$PWD/$bad/piece_100m.json"
run coordinates_1e308 "$here/pattern_piece.rhai" --set input="$PWD/$bad/coordinates_1e308.json"
run edge_length_1e5 "$here/edge_length_1e5.rhai" --set input="$PWD/scripts/patterns/aaron.garment.json"
run make_sequence_fps "$here/make_sequence_fps.rhai" --set input="$data/motion/cmu_bvh/002_01.bvh" --set out="$work/seq" --set fps=1e9
run bvh_frame_time "$here/make_sequence_fps.rhai" --set input="$work/frame_time_1e9.bvh" --set out="$work/seq2"
# the benchmark at 100000 × 100000 particles
t0=$(date +%s.%N)
( ulimit -v 4000000; RAYON_NUM_THREADS=1 timeout 20 "$bin" bench --sizes 100000 ) >"$work/bench.log" 2>&1
printf '%-24s rc=%-3s %6.1fs           %s\n' bench_100000 "$?" "$(echo "$(date +%s.%N) - $t0" | bc)" "$(tail -1 "$work/bench.log" | cut -c1-170)"

#!/bin/sh
# Runs the same scene with two emilion binaries and prints the largest distance between their
# final shapes' vertices (m): the "no accuracy lost" check of issue 53.
# Usage: scripts/compare_shapes.sh BASE_BINARY NEW_BINARY [SCRIPT] [N]
#   e.g. scripts/compare_shapes.sh /work/main/target/release/emilion target/release/emilion scripts/hang.rhai 64
# SCRIPT must write $out/<name>.obj (hang.rhai: hang.obj; drape_sphere.rhai: drape_sphere/drape_sphere.obj).
set -eu
base=$1; new=$2; script=${3:-scripts/hang.rhai}; n=${4:-64}
tmp=$(mktemp -d)
"$base" run "$script" --set out="$tmp/base" --set n="$n" >/dev/null
"$new" run "$script" --set out="$tmp/new" --set n="$n" >/dev/null
python3 - "$tmp/base" "$tmp/new" <<'PY'
import sys, os, math
def objs(d):
    for root, _, files in os.walk(d):
        for f in sorted(files):
            if f.endswith(".obj"):
                yield os.path.relpath(os.path.join(root, f), d)
def verts(p):
    return [tuple(map(float, l.split()[1:4])) for l in open(p) if l.startswith("v ")]
worst = 0.0
for rel in objs(sys.argv[1]):
    a, b = verts(os.path.join(sys.argv[1], rel)), verts(os.path.join(sys.argv[2], rel))
    assert len(a) == len(b), f"{rel}: {len(a)} vs {len(b)} vertices"
    d = max(math.dist(p, q) for p, q in zip(a, b))
    print(f"{rel}: {len(a)} vertices, largest distance {d:.3e} m")
    worst = max(worst, d)
print(f"largest distance {worst:.3e} m ({'within' if worst <= 1e-6 else 'beyond'} 1e-6 m)")
PY
rm -rf "$tmp"

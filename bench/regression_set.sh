#!/usr/bin/env bash
# The regression set: renders, eval lines (scalar and --batch) and estimate tables whose bytes a
# change that claims "the same numbers" must keep. Run it with the binary
# before and after the change, then compare the two folders:
#
#   bench/regression_set.sh OLD/target/release/lobe /tmp/before
#   bench/regression_set.sh target/release/lobe /tmp/after
#   bench/regression_set.sh --compare /tmp/before /tmp/after
#
# The estimate tables are compared without their times (time_s and
# efficiency change from run to run). Run from the repository root.
set -euo pipefail
if [ "${1:-}" = "--compare" ]; then
    a=$2; b=$3; bad=0
    for f in "$a"/*; do
        g="$b/$(basename "$f")"
        case "$f" in
        *.json)
            if ! python3 - "$f" "$g" <<'PY'
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in ("time_s", "efficiency")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
sys.exit(0 if a == b else 1)
PY
            then echo "differs: $(basename "$f")"; bad=1; fi ;;
        *) cmp -s "$f" "$g" || { echo "differs: $(basename "$f")"; bad=1; } ;;
        esac
    done
    [ $bad = 0 ] && echo "the same: $(ls "$a" | wc -l) files"
    exit $bad
fi
lobe=$1; out=$2
mkdir -p "$out"
render() { "$lobe" render "$@" --threads 2 -q; }
for s in mis vndf brdf light mis-balance mis-power; do
    render examples/scene.toml --spp 8 --strategy "$s" --out "$out/scene_$s"
done
render examples/scene.toml --spp 8 --loop scalar --out "$out/scene_scalar"
render crates/lobe-render/scenes/spheres.toml --spp 4 --out "$out/spheres"
materials=(
    '{"type":"cook-torrance","alpha":0.2,"kd":0.3}'
    '{"type":"cook-torrance","distribution":"beckmann","alpha_u":0.1,"alpha_v":0.4,"fresnel":{"type":"conductor"}}'
    '{"type":"phong","exponent":50,"kd":0.2}'
    '{"type":"blinn-phong","exponent":40}'
    '{"type":"lambert"}'
)
k=0
for m in "${materials[@]}"; do
    k=$((k + 1))
    "$lobe" estimate --material "$m" --theta 50 --light sky:20:70 --samples 20000 \
        --strategy all --json > "$out/estimate_$k.json" 2>/dev/null
    python3 - > "$out/lines_$k.jsonl" <<'PY'
import json, math, random
random.seed(1)
for i in range(2000):
    t, p = random.random() * 1.4, random.random() * 6.28
    wo = [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]
    print(json.dumps({"wo": wo, "u": [random.random(), random.random()], "uc": random.random(), "strategy": "brdf"}))
    t, p = random.random() * 1.5, random.random() * 6.28
    print(json.dumps({"wo": wo, "wi": [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]}))
PY
    "$lobe" eval --material "$m" < "$out/lines_$k.jsonl" > "$out/eval_$k.jsonl"
    "$lobe" eval --batch --material "$m" < "$out/lines_$k.jsonl" > "$out/eval_batch_$k.jsonl"
done
echo "wrote $(ls "$out" | wc -l) files to $out"

#!/usr/bin/env bash
# The trace benchmark's thread sweep: vkrt_tracebench in a fresh process per thread count (vkrt reads VKRT_THREADS
# once, at its first device), then one JSON with every run and the scaling efficiency per figure:
# rate(T) / (T * rate(1)).
# Usage: bench/tracebench_sweep.sh [build dir (build-rel)] [out.json (tracebench.json)] [threads ("1 2 4 8 16")]
#        [extra vkrt_tracebench arguments...]
set -euo pipefail
build=${1:-build-rel}
out=${2:-tracebench.json}
threads=${3:-1 2 4 8 16}
shift $(($# < 3 ? $# : 3))
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
files=()
for t in $threads; do
  echo "== $t threads" >&2
  "$build/bench/vkrt_tracebench" --threads "$t" --json "$dir/t$t.json" "$@"
  files+=("$dir/t$t.json")
done
python3 - "$out" "${files[@]}" <<'PY'
import json, sys
out, files = sys.argv[1], sys.argv[2:]
runs = [json.load(open(f)) for f in files]
base = min(runs, key=lambda r: r["threads"])
def rate(run, n, path):
    for s in run["sizes"]:
        if s["triangles"] == n:
            v = s
            for k in path:
                v = v[k]
            return v
    return None
figures = [("primary", "vkrt_mrays_per_s"), ("primary", "embree1_mrays_per_s"), ("primary", "embree8_mrays_per_s"),
           ("paths", "vkrt_mrays_per_s"), ("paths", "embree1_mrays_per_s"), ("paths", "embree8_mrays_per_s"),
           ("blas", "vkrt_mtris_per_s"), ("blas", "embree_commit_mtris_per_s"),
           ("tlas", "vkrt_minst_per_s"), ("tlas", "embree_commit_minst_per_s")]
scaling = []
for s in base["sizes"]:
    n = s["triangles"]
    for path in figures:
        one = rate(base, n, path)
        row = {"triangles": n, "figure": ".".join(path), "base_threads": base["threads"], "efficiency": {}}
        for r in runs:
            v = rate(r, n, path)
            if one and v is not None:
                row["efficiency"][str(r["threads"])] = round(v / (one * r["threads"] / base["threads"]), 4)
        scaling.append(row)
json.dump({"program": "vkrt_tracebench sweep", "machine": runs[-1]["machine"], "date": runs[-1]["date"],
           "git_commit": runs[-1]["git_commit"], "runs": runs, "scaling": scaling}, open(out, "w"), indent=1)
print("wrote", out, file=sys.stderr)
print("%-9s %-30s %s" % ("triangles", "figure", "  ".join("%5sT" % r["threads"] for r in runs)))
for row in scaling:
    print("%-9d %-30s %s" % (row["triangles"], row["figure"],
                             "  ".join("%6.2f" % row["efficiency"].get(str(r["threads"]), float("nan")) for r in runs)))
print("(scaling efficiency: rate(T) / (T * rate(%d)))" % base["threads"])
PY

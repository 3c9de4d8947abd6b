#!/usr/bin/env bash
# MMG (`mmgs_O3`, MMG 5.7 from the `pymmg` wheel) on shared meshes with the protocol of
# ../shared/PEERS.md: input scaled to bounding-box diagonal 1, the curvature metric of Sec. 3.1
# divided by L_tar² (L_tar = 1.5·L_avg), its normal eigenvalue set to the larger tangent one
# (`examples/mmg_sol.rs`), then `conemesh eval` of MMG's output against the scaled input.
#
#   reference/mmg/run.sh MESH... [-- MMG_OPTIONS]
#
# MMG_OPTIONS default to `-nr` (PEERS.md's `mmgs-nr`); `-- -nr -hausd 10 -hgrad -1` is its
# `mmgs-nogeo-nograd`; `-- -hausd 0.01` runs MMG's own defaults (ridge detection on).
#
# Needs network access once (pip download of pymmg into reference/mmg/build/). Prints one
# `conemesh eval` row per mesh; the outputs stay in reference/mmg/build/.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$here/build"
mkdir -p "$build"
meshes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do meshes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
opts=("$@")
[ ${#opts[@]} -eq 0 ] && opts=(-nr)
[ ${#meshes[@]} -eq 0 ] && { echo "usage: $0 MESH... [-- MMG_OPTIONS]" >&2; exit 2; }
mmgs="$build/pymmg/mmgs/mmgs_O3"
if [ ! -x "$mmgs" ]; then
  python3 -m pip download pymmg==1.0.0 --no-deps --only-binary=:all: -d "$build/wheel" >&2
  python3 -m zipfile -e "$build"/wheel/pymmg-1.0.0-*.whl "$build/pymmg"
  chmod +x "$mmgs"
fi
(cd "$root" && cargo build --release --quiet --bin conemesh --example mmg_sol)
conemesh="$root/target/release/conemesh"
for m in "${meshes[@]}"; do
  name="$(basename "${m%.*}")"
  "$root/target/release/examples/mmg_sol" "$m" "$build/$name" 2>/dev/null
  t0=$(date +%s.%N)
  "$mmgs" -in "$build/$name.mesh" -sol "$build/$name.sol" -out "$build/$name-mmgs.mesh" \
    "${opts[@]}" -v -1 >/dev/null
  python3 -c 'import sys, time; print(f"{sys.argv[1]}: mmgs {time.time() - float(sys.argv[2]):.2f} s", file=sys.stderr)' "$name" "$t0"
  "$conemesh" eval --input "$build/$name.mesh" --output "$build/$name-mmgs.mesh" \
    --name "$name-mmgs" --no-header | head -1
done

#!/usr/bin/env bash
# Issue 13's safety net: render a fixed set of outputs and print one SHA-256 per file, so a
# refactor can show every image is unchanged bit for bit. Usage:
#   scripts/golden.sh > before.txt; (refactor); scripts/golden.sh > after.txt; diff before.txt after.txt
# Needs ../shared/scenes for the scene files and mpirun (Open MPI) for the cluster render.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build -q --release --features mpi --bin igi
igi=${CARGO_TARGET_DIR:-$PWD/target}/release/igi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
small=(--width 96 --height 64)
r() { "$igi" render "$@" >/dev/null 2>&1; }

for s in cornell-box shirley-room procedural-room procedural-room-lambert animated-room; do
    r "$s" "${small[@]}" -o "$out/$s.png"
    r "$s" "${small[@]}" --aa 1 -o "$out/$s.exr"
done
for f in scenes/*.toml; do
    n=$(basename "$f" .toml)
    r "$f" "${small[@]}" -o "$out/$n.png"
    r "$f" "${small[@]}" --aa 1 -o "$out/$n.exr"
done
r cornell-box "${small[@]}" --frames 8 -o "$out/cornell-frames8.png"
r cornell-box "${small[@]}" --frames 8 -o "$out/cornell-frames8.exr"
r animated-room "${small[@]}" --sequence 4 --fps 4 -o "$out/animated-seq.png"
r cornell-box "${small[@]}" --mode path --spp 4 -o "$out/cornell-path.exr"
r cornell-box "${small[@]}" --no-filter --interleave 2x2 --vpls 6 -o "$out/cornell-raw.png"
r cornell-box "${small[@]}" --mode path --spp 4 -o "$out/cornell-path.png"
r cornell-box "${small[@]}" --moving-frame -o "$out/cornell-moving.png"
r cornell-box "${small[@]}" --seed 3 --tile-size 16 --coarse-interleave 1 -o "$out/cornell-seed3.png"
r shirley-room "${small[@]}" --compensate --clamp 0.3 --frames 2 --aa 2 -o "$out/shirley-compensate.exr"
r animated-room "${small[@]}" --time 1.5 --exposure 1 -o "$out/animated-time.png"
S=../shared/scenes
for f in $S/gltf-samples/DamagedHelmet/glTF/DamagedHelmet.gltf $S/gltf-samples/Fox/glTF/Fox.gltf \
    $S/stanford-bunny/bun_zipper_res2.ply $S/cornell-box/CornellBox-Original.obj $S/lost-empire/lost_empire.obj; do
    r "$f" "${small[@]}" -o "$out/$(basename "$f").png"
done
mpirun --allow-run-as-root --oversubscribe -n 3 "$igi" render cornell-box "${small[@]}" --cluster \
    -o "$out/cornell-cluster.png" >/dev/null 2>&1
mpirun --allow-run-as-root --oversubscribe -n 2 "$igi" render animated-room "${small[@]}" --cluster \
    --sequence 3 --fps 4 -o "$out/animated-cluster.png" >/dev/null 2>&1
(cd "$out" && sha256sum -- *)

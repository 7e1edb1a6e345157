#!/usr/bin/env bash
# Runs every cargo-fuzz target of fuzz/ for SECONDS_PER_TARGET seconds each (default 120),
# one after the other on one core, and prints the executions each one ran.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET]
#
# cargo-fuzz needs nightly-only compiler flags (-Z sanitizer=...); RUSTC_BOOTSTRAP=1 lets the
# stable toolchain accept them. Corpora start from the small files of ../shared/scenes when
# that directory exists and are kept in fuzz/corpus/<target>; crashes land in
# fuzz/artifacts/<target> (both ignored by git). Exits non-zero if a target found a crash.
set -euo pipefail

seconds="${1:-120}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
shared="$root/../shared/scenes"
cd "$root/fuzz"

if ! command -v cargo-fuzz >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi
export RUSTC_BOOTSTRAP=1

# Seed files per target, relative to shared/scenes.
declare -A seeds=(
    [obj]="cornell-box/CornellBox-Original.obj cornell-box/CornellBox-Original.mtl cornell-variants/CornellBox-Mirror.obj cornell-variants/CornellBox-Mirror.mtl sponza-dabrovic/sponza.mtl"
    [ply]="stanford-bunny/bun_zipper_res4.ply"
    [gltf]="gltf-samples/Box/glTF-Binary/Box.glb gltf-samples/Box/glTF-Embedded/Box.gltf gltf-samples/Cameras/glTF-Embedded/Cameras.gltf gltf-samples/BoxTextured/glTF-Binary/BoxTextured.glb gltf-samples/BoxAnimated/glTF-Binary/BoxAnimated.glb"
    [scene_file]=""
)

status=0
for target in obj ply gltf scene_file; do
    corpus="corpus/$target"
    mkdir -p "$corpus"
    for file in ${seeds[$target]}; do
        if [[ -f "$shared/$file" ]]; then
            cp -n "$shared/$file" "$corpus/" 2>/dev/null || true
        fi
    done
    if [[ "$target" == scene_file && ! -e "$corpus/seed.toml" ]]; then
        printf '%s\n' '[camera]' 'position = [0, 1, 3.5]' 'target = [0, 1, 0]' 'fov = 39.3' \
            '[[mesh]]' 'file = "a.obj"' 'rotate = [0, 90, 0]' 'instances = [ { translate = [1, 0, 0] }, { scale = 2 } ]' \
            'material = { diffuse = [0.5, 0.5, 0.5] }' '[[light]]' 'type = "quad"' 'position = [0, 1.9, 0]' \
            'u = [0.2, 0, 0]' 'v = [0, 0, 0.2]' 'radiance = [10, 10, 10]' > "$corpus/seed.toml"
    fi
    if [[ "$target" == scene_file && ! -e "$corpus/shading.toml" ]]; then
        printf '%s\n' '[[light]]' 'type = "quad"' 'position = [0, 1, 0]' 'u = [1, 0, 0]' 'v = [0, 0, 1]' 'radiance = [1, 1, 1]' \
            '[[shader]]' 'target = "light[0]"' 'type = "brick"' 'scale = 2.0' 'size = [3, 1, 1.5]' \
            'mortar = 0.1' 'bump = 0.01' 'colors = [[0.6, 0.2, 0.1], [0.8, 0.8, 0.8]]' \
            '[[shader]]' 'target = "light[0]"' 'type = "marble"' 'octaves = 4' 'turbulence = 5' \
            '[environment]' 'color = [0.3, 0.45, 0.8]' > "$corpus/shading.toml"
    fi
    if [[ "$target" == scene_file && ! -e "$corpus/animation.toml" ]]; then
        printf '%s\n' '[[light]]' 'type = "quad"' 'position = [0, 1, 0]' 'u = [1, 0, 0]' 'v = [0, 0, 1]' 'radiance = [1, 1, 1]' \
            '[light.animation]' 'interpolation = "smooth"' \
            'keys = [ { time = 0, position = [0, 1, 0] }, { time = 2, rotate = [0, 90, 0], position = [1, 1, 0] } ]' \
            '[[light]]' 'type = "spot"' 'position = [0, 2, 0]' 'direction = [0, -1, 0]' 'angle = 40' 'intensity = [1, 1, 1]' \
            '[light.animation]' 'loop = false' 'interpolation = "step"' \
            'keys = [ { time = 0, intensity = [1, 0, 0] }, { time = 1, direction = [1, -1, 0] } ]' > "$corpus/animation.toml"
    fi
    log="$(mktemp)"
    echo "== $target: ${seconds}s"
    if cargo fuzz run "$target" "$corpus" -- -max_total_time="$seconds" -jobs=1 -workers=1 \
        -print_final_stats=1 -rss_limit_mb=4096 >"$log" 2>&1; then
        result="ok"
    else
        result="FAILED (see fuzz/artifacts/$target)"
        status=1
    fi
    # With -jobs, libFuzzer writes the job's own output to fuzz-<job>.log.
    [[ -f fuzz-0.log ]] && cat fuzz-0.log >>"$log" && rm -f fuzz-0.log
    executions="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || echo '?')"
    echo "   $target: $result, $executions executions"
    if [[ "$result" != ok ]]; then
        grep -A2 "panicked at" "$log" || true
        tail -12 "$log"
    fi
    rm -f "$log"
done
exit "$status"

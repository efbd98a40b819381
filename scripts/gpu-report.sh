#!/usr/bin/env bash
# The GPU report: one command that measures rastergi on this machine's GPU and writes the
# figures as markdown, one `## ` section per measurement, each with the exact command it ran
# and its output:
#
#   Adapter       rastergi info
#   Photons       photons/s, GPU against the CPU twin (bench photons)
#   Rays          rays/s of each kind the passes cast, GPU kernel against the CPU twin, on
#                 the Cornell box and a 1 M-triangle mesh, on both ray paths (the compute
#                 BVH and, where the GPU has them, hardware ray queries with their build
#                 time and memory) side by side (bench rays)
#   Gather        directions/s of each gather (raster, lists, trace) at 512² and 1024²
#   Viewer loop   frames/s and iterations/s of the viewer's frame loop at 1920×1080, no
#                 window (bench frames)
#   Convergence   time to 5 % and 2 % relative RMSE at 1024² against a reference made here
#                 by rastergi's path tracer (two long renders), for the renderer and the
#                 path tracer (bench converge)
#   Mitsuba       the same with Mitsuba 3 `cuda_ad_rgb` beside them, when python3 can import
#                 it (otherwise the section says why it was skipped)
#   Denoiser      milliseconds per application of the denoiser at 256² and 1920×1080
#                 (bench denoise)
#   Memory        GPU memory at 1920×1080 (bench memory)
#
# Usage: scripts/gpu-report.sh [--quick] [--out FILE.md] [--binary PATH]
#
#   --quick        tiny sizes and runs of a second or two: under a minute on lavapipe (CPU
#                  Vulkan). The test suite runs it (crates/rastergi-cli/tests/gpu_report.rs)
#                  so the script keeps working; its figures are no performance figures.
#   --out FILE     the report (default gpu-report.md); the convergence plots and CSVs are
#                  written beside it (FILE-converge.png, ...)
#   --binary PATH  the rastergi binary to measure (default: `cargo build --release`, then
#                  the build's target/release/rastergi)
#
# Time: each step has a budget (below, in seconds) and is stopped if it runs past it, so the
# full report takes at most the sum of the budgets, 495 s, plus the build. The budgets fit
# a real GPU: the steps with fixed work (photons, gather, memory) need a few seconds there,
# and the others run for a given time (--seconds, --max-seconds) chosen within them. In
# --quick mode the budgets are only caps against a hang. A step that fails or is stopped is
# recorded as FAILED in its section and the report goes on; the script then exits with 1.
set -euo pipefail

usage() { sed -n '/^# Usage:/,/^#   --binary/p' "$0" | sed 's/^# \{0,1\}//'; }

quick=0
out=gpu-report.md
binary=
while [ $# -gt 0 ]; do
    case "$1" in
        --quick) quick=1 ;;
        --out)
            [ $# -ge 2 ] || { echo "gpu-report: --out needs a file name" >&2; exit 2; }
            out=$2
            shift
            ;;
        --binary)
            [ $# -ge 2 ] || { echo "gpu-report: --binary needs a path" >&2; exit 2; }
            binary=$2
            shift
            ;;
        -h | --help) usage; exit 0 ;;
        *) echo "gpu-report: unknown option '$1'" >&2; usage >&2; exit 2 ;;
    esac
    shift
done

# Paths given relative to where the script was started; it then runs in the repository root
# (bench --mitsuba finds scripts/mitsuba_reference.py there).
absolute() {
    local dir
    dir=$(cd "$(dirname "$1")" 2>/dev/null && pwd) || { echo "gpu-report: $1: no such directory" >&2; exit 2; }
    printf '%s/%s' "${dir%/}" "$(basename "$1")"
}
out=$(absolute "$out")
repo=$(cd "$(dirname "$0")/.." && pwd)
if [ -n "$binary" ]; then
    binary=$(absolute "$binary")
else
    echo "gpu-report: cargo build --release" >&2
    (cd "$repo" && cargo build --release)
    target=${CARGO_TARGET_DIR:-target}
    case "$target" in /*) ;; *) target=$repo/$target ;; esac
    binary=$target/release/rastergi
fi
[ -x "$binary" ] || { echo "gpu-report: $binary is not an executable" >&2; exit 2; }
cd "$repo"

work=$(mktemp -d "${TMPDIR:-/tmp}/gpu-report.XXXXXX")
trap 'rm -rf "$work"' EXIT
stem=${out%.md}
started=$(date +%s)

if [ "$quick" = 1 ]; then
    mode="quick (tiny sizes and runs of a second or two, for CI and lavapipe: its figures are no performance figures)"
    # Steps and their caps (s): every one takes a few seconds on lavapipe.
    B_INFO=60 B_PHOTONS=60 B_RAYS=30 B_GATHER=120 B_FRAMES=60 B_REF=60 B_COMPARE=60 B_CONVERGE=60 B_MITSUBA=120 B_DENOISE=60 B_MEMORY=60
    PHOTONS=(--photons 65536 --grid 32 --repeats 1)
    RAYS=(--size 32 --repeats 1)
    RAYS_MESH=spheres:20000
    GATHER=(--sizes 64,128 --iterations 4 --bundle 256 --photons 65536 --grid 32)
    FRAMES=(--width 160 --height 90 --seconds 1 --photons 65536 --grid 32)
    SIZE=64 REF_SECONDS=1 CONVERGE_SECONDS=1 MITSUBA_SECONDS=1
    MEMORY=(--width 160 --height 90 --grid 32 --bundle 256)
    DENOISE_SIZES=(64x48)
    DENOISE=(--repeats 1 --iterations 2)
else
    mode="full"
    # Budgets (s), 495 in all (the rays', the reference's and the denoiser's twice):
    B_INFO=10      # adapter query
    B_PHOTONS=30   # 4 GPU runs of 4 M photons, then the CPU twin once (a few s on 8+ cores)
    B_RAYS=20      # each of 2 scenes: 5 kinds x 4 GPU runs of 1 M rays + the CPU twin once each
    B_GATHER=45    # 2 sizes x 3 gathers: a renderer each (4 M photons), 2 + 16 iterations
    B_FRAMES=30    # set-up and warm-up, then 3 x 6 s (panel shown, hidden, one iteration per frame)
    B_REF=55       # each of the two reference renders: 50 s of path tracing + set-up
    B_COMPARE=5    # the two halves of the reference against each other
    B_CONVERGE=45  # 15 s each for the renderer and the path tracer, + set-up and read-backs
    B_MITSUBA=120  # 8 s each for the two, Mitsuba doubling its spp past 8 s (<= 4 x 8 s)
    #                plus its process start-up (JIT) for each of ~12 runs
    B_DENOISE=20   # each size: a renderer, 4 iterations, 5 applications (lavapipe: 14 s each at 1080p)
    B_MEMORY=20    # one renderer at 1920x1080, grid 128, bundle 2048, auto's trial iterations
    PHOTONS=(--photons 4194304 --repeats 3)
    RAYS=(--size 1024 --repeats 3)
    RAYS_MESH=spheres:1000000
    GATHER=(--sizes 512,1024 --iterations 16)
    FRAMES=(--width 1920 --height 1080 --seconds 6)
    SIZE=1024 REF_SECONDS=50 CONVERGE_SECONDS=15 MITSUBA_SECONDS=8
    MEMORY=()
    DENOISE_SIZES=(256x256 1920x1080)
    DENOISE=()
fi

# The report, written as it goes.
report() { printf '%s\n' "$@" >>"$out"; }
commit=$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)
if [ "$commit" != unknown ] && [ -n "$(git -C "$repo" status --porcelain --untracked-files=no 2>/dev/null)" ]; then
    commit="$commit (with uncommitted changes)"
fi
cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | sed 's/.*: //' || true)
cores=$(nproc 2>/dev/null || getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?')
: >"$out"
report "# rastergi GPU report" ""
report "- date: $(date -u '+%Y-%m-%d %H:%M UTC')"
report "- commit: $commit"
report "- host: $(hostname 2>/dev/null || uname -n), $(uname -srm), ${cpu:-CPU unknown}, $cores cores"
report "- mode: $mode"
report "- \`rastergi\` in the commands: $binary; \`\$W\`: a temporary directory"
report ""

# The command as shown: the binary as `rastergi`, the work directory as $W.
shown() {
    local a s=
    for a in "$@"; do
        a=${a//"$binary"/rastergi}
        a=${a//"$work"/\$W}
        case "$a" in
            *[!A-Za-z0-9_./,:=@%+\$-]*) a="'${a//\'/\'\\\'\'}'" ;;
        esac
        s="$s${s:+ }$a"
    done
    printf '%s' "$s"
}

failed=()
summary=()
# step NAME BUDGET COMMAND...: runs COMMAND (at most BUDGET seconds), appends it and its
# output to the report; a failure is recorded and returns 1.
step() {
    local name=$1 budget=$2
    shift 2
    local log=$work/step.log t0 rc=0
    echo "gpu-report: $name: $(shown "$@")" >&2
    t0=$(date +%s.%N)
    if command -v timeout >/dev/null 2>&1; then
        timeout -k 5 "$budget" "$@" >"$log" 2>&1 || rc=$?
    else
        "$@" >"$log" 2>&1 || rc=$?
    fi
    local seconds
    seconds=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    report '```sh' "$(shown "$@")" '```' '```text'
    local line
    while IFS= read -r line || [ -n "$line" ]; do
        case "$line" in *XDG_RUNTIME_DIR*) continue ;; esac
        report "${line//"$work"/\$W}"
    done <"$log"
    report '```'
    if [ "$rc" = 0 ]; then
        report "($seconds s of a $budget s budget)" ""
        summary+=("| $name | ok | $seconds |")
        return 0
    fi
    local why="exit status $rc"
    if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
        why="stopped at its budget of $budget s"
    fi
    report "**FAILED** ($why, after $seconds s)" ""
    summary+=("| $name | **FAILED** ($why) | $seconds |")
    failed+=("$name")
    return 1
}

report "## Adapter" ""
step "rastergi info" "$B_INFO" "$binary" info || true
if grep -q '^type: *Cpu' "$out"; then
    report "This adapter is a CPU implementation of Vulkan (lavapipe or similar): no figure below is a GPU figure." ""
fi

report "## Photons" ""
report "Photon tracing into the photon map, photons/s on the GPU against the CPU twin (rayon)." ""
step "photons" "$B_PHOTONS" "$binary" bench photons "${PHOTONS[@]}" || true

report "## Rays" ""
report "Rays/s of each kind the passes cast, the GPU kernel (trace of bvh.wgsl) against the CPU twin (rayon), hit for hit." ""
step "rays: cornell" "$B_RAYS" "$binary" bench rays cornell "${RAYS[@]}" || true
step "rays: $RAYS_MESH" "$B_RAYS" "$binary" bench rays "$RAYS_MESH" "${RAYS[@]}" || true

report "## Gather" ""
report "Final-gather directions/s of the three implementations (4 directions per iteration)." ""
step "gather" "$B_GATHER" "$binary" bench gather "${GATHER[@]}" || true

report "## Viewer loop" ""
report "The viewer's per-frame work without a window: batched iterations, resolve, display pass."
report "No present, hence no vsync: frames/s is what the GPU sustains." ""
step "viewer loop" "$B_FRAMES" "$binary" bench frames "${FRAMES[@]}" || true

report "## Convergence" ""
report "Relative RMSE (emitter pixels masked) against a reference rendered here by rastergi's"
report "path tracer: two renders of up to $REF_SECONDS s (${SIZE}², seeds 1001 and 1002), averaged." ""
if [ "$quick" = 1 ]; then
    report "Quick mode: the reference has a few seconds of path tracing at ${SIZE}², so it is"
    report "itself noisy (see its noise below) and the times to 5 % and 2 % mean little: this"
    report "section shows that the measurement runs, not how fast rastergi converges." ""
fi
ref_a=$work/ref-a.exr ref_b=$work/ref-b.exr
ref_ok=1
for half in a:1001 b:1002; do
    step "reference ${half%%:*}" "$B_REF" "$binary" render cornell --method path --width "$SIZE" --height "$SIZE" \
        --seed "${half#*:}" --iterations 4000000000 --max-seconds "$REF_SECONDS" --out "$work/ref-${half%%:*}.exr" ||
        ref_ok=0
done
if [ "$ref_ok" = 1 ]; then
    report "The reference's own noise: the relative RMSE between its two halves, halved, is that of their mean." ""
    if step "reference noise" "$B_COMPARE" "$binary" compare "$ref_a" "$ref_b" --mask-emitters; then
        noise=$(awk '/^relative RMSE:/ { printf "%.2f", 50 * $3 }' "$work/step.log")
        report "So the reference is within about **${noise} %** of the converged image: errors measured"
        report "against it near or below that are reference noise (they add in quadrature)." ""
    fi
    step "convergence" "$B_CONVERGE" "$binary" bench converge --reference "$ref_a,$ref_b" \
        --seconds "$CONVERGE_SECONDS" --count-rays --csv "$stem-converge.csv" --plot "$stem-converge.png" || true
    if [ -f "$stem-converge.csv" ]; then
        report "Last point of each curve ($(basename "$stem")-converge.csv holds them all):" ""
        # With the reference's noise n known: sqrt(e² - n²) estimates the error against the
        # converged image.
        awk -F, -v n="${noise:-}" '
            NR > 1 {
                # The method is quoted and may hold commas: the figures are the last four fields
                # (seconds, samples, relative RMSE, rays per pixel: empty for Mitsuba).
                name = $0
                sub(/,[^,]*,[^,]*,[^,]*,[^,]*$/, "", name)
                gsub(/"/, "", name)
                e = 100 * $(NF - 1)
                s = sprintf("- %s: %.2f %% after %.2f s of rendering (%d samples per pixel", name, e, $(NF - 3), $(NF - 2))
                s = s ($NF != "" ? sprintf(", %.0f rays per pixel traced", $NF) : "") ")"
                if (n != "") s = s sprintf("; %.2f %% once the reference noise is taken out", sqrt(e * e > n * n ? e * e - n * n : 0))
                last[name] = s
                if (!(name in seen)) { seen[name] = 1; order[++k] = name }
            }
            END { for (i = 1; i <= k; i++) print last[order[i]] }' "$stem-converge.csv" >>"$out"
        report "" "![relative RMSE against time]($(basename "$stem")-converge.png)" ""
    fi
else
    report "**FAILED**: no reference, so no convergence measurement." ""
    failed+=("convergence")
    summary+=("| convergence | **FAILED** (no reference) | 0 |")
fi

report "## Mitsuba" ""
probe="import mitsuba, numpy; mitsuba.set_variant('cuda_ad_rgb')"
if ! command -v python3 >/dev/null 2>&1; then
    report "Skipped: no python3 on this machine." ""
    summary+=("| mitsuba | skipped (no python3) | 0 |")
elif ! why=$(python3 -c "$probe" 2>&1); then
    why=$(printf '%s\n' "$why" | grep -v '^\s*$' | tail -n 1)
    report "Skipped: \`python3 -c \"$probe\"\` failed: $why" ""
    summary+=("| mitsuba | skipped (no mitsuba with cuda_ad_rgb) | 0 |")
elif [ "$ref_ok" = 0 ]; then
    report "**FAILED**: no reference (see Convergence)." ""
    failed+=("mitsuba")
    summary+=("| mitsuba | **FAILED** (no reference) | 0 |")
else
    report "Mitsuba 3's \`path\` integrator in \`cuda_ad_rgb\` beside rastergi, against the same reference"
    report "(doubling spp; each run's process start-up and JIT, measured at 1 spp, subtracted)." ""
    step "mitsuba" "$B_MITSUBA" "$binary" bench converge --reference "$ref_a,$ref_b" --seconds "$MITSUBA_SECONDS" \
        --mitsuba --mitsuba-variant cuda_ad_rgb --csv "$stem-mitsuba.csv" --plot "$stem-mitsuba.png" || true
fi

report "## Denoiser" ""
report "One application of the denoiser (guide and regression, tests/denoise.rs) to the accumulated image." ""
for size in "${DENOISE_SIZES[@]}"; do
    step "denoiser $size" "$B_DENOISE" "$binary" bench denoise cornell --width "${size%x*}" --height "${size#*x}" \
        ${DENOISE[@]+"${DENOISE[@]}"} || true
done

report "## Memory" ""
report "GPU memory from the device allocator's report, after set-up and while rendering." ""
step "memory" "$B_MEMORY" "$binary" bench memory ${MEMORY[@]+"${MEMORY[@]}"} || true

report "## Summary" ""
report "| step | result | seconds |" "|---|---|---|"
report "${summary[@]}"
report "" "Total: $(($(date +%s) - started)) s (the build not counted)."
echo "gpu-report: wrote $out" >&2
if [ ${#failed[@]} -gt 0 ]; then
    echo "gpu-report: FAILED: ${failed[*]}" >&2
    exit 1
fi

#!/usr/bin/env bash
# The one-call GPU benchmark: `dvr bench` on a machine that may lack what a desktop has,
# then one tarball to bring back.
#
#   tools/gpu-bench.sh [--out DIR] [--bin DVR] [--vulkan-deb FILE] [--font FILE]
#                      [--assets DIR] [-- extra `dvr bench` arguments]
#
# By default `dvr bench` profiles every denoiser at 256x256, 1280x720 and 1920x1080 and
# runs the eval suite at 256x256 against 1024-spp references (see `dvr bench --help`;
# e.g. `-- --sizes 16x16 --frames 3 --eval-scene phantom/orbit --eval-size 16x16
# --eval-frames 2 --ref-spp 4` is the tiny run CI does on lavapipe).
#
#   --out DIR         results (default out/gpu-bench); written as DIR and DIR.tar.gz.
#                     The eval's full output (images) goes to DIR-eval, not in the tar.
#   --bin DVR         the dvr binary (default: $DVR_BIN, else target/release/dvr of this
#                     checkout, else `dvr` on PATH). A release build made on Debian 12
#                     links only libc/libm/libgcc and runs on other x86-64 Linux machines.
#   --vulkan-deb FILE Debian's libvulkan1_*.deb, for a machine that has a GPU's Vulkan
#                     driver but no Vulkan loader: it is unpacked into DIR-loader and put
#                     on LD_LIBRARY_PATH (no root needed). Only used when no loader is
#                     found.
#   --font FILE       a TrueType font for the plots (sets DVR_FONT), for a machine
#                     without fonts.
#   --assets DIR      the assets folder (sets DVR_ASSETS), for a binary away from its
#                     checkout (default: assets/ of this checkout when present).
#
# It also records nvidia-smi's view of the GPU when that command exists.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out=out/gpu-bench
bin="${DVR_BIN:-}"
deb=""
bench_args=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --out) out="$2"; shift 2 ;;
        --bin) bin="$2"; shift 2 ;;
        --vulkan-deb) deb="$2"; shift 2 ;;
        --font) export DVR_FONT="$2"; shift 2 ;;
        --assets) export DVR_ASSETS="$2"; shift 2 ;;
        --) shift; bench_args=("$@"); break ;;
        -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
        *) echo "gpu-bench: unknown argument $1 (see --help)" >&2; exit 1 ;;
    esac
done

if [[ -z "$bin" ]]; then
    if [[ -x "$here/target/release/dvr" ]]; then
        bin="$here/target/release/dvr"
    else
        bin="$(command -v dvr || true)"
    fi
fi
if [[ -z "$bin" || ! -x "$bin" ]]; then
    echo "gpu-bench: no dvr binary (build with cargo build --release, or pass --bin)" >&2
    exit 1
fi
if [[ -z "${DVR_ASSETS:-}" && -d "$here/assets" ]]; then
    export DVR_ASSETS="$here/assets"
fi

has_loader() {
    # ldconfig's list is read whole before it is searched: `ldconfig -p | grep -q` under
    # pipefail fails at random (grep exits at the first match and ldconfig dies of SIGPIPE).
    local cache
    cache="$({ ldconfig -p || /sbin/ldconfig -p; } 2>/dev/null || true)"
    if grep -q 'libvulkan\.so\.1' <<< "$cache"; then
        return 0
    fi
    local dirs d
    IFS=: read -ra dirs <<< "${LD_LIBRARY_PATH:-}"
    for d in "${dirs[@]}"; do
        [[ -e "$d/libvulkan.so.1" ]] && return 0
    done
    return 1
}
if ! has_loader; then
    if [[ -z "$deb" ]]; then
        echo "gpu-bench: no Vulkan loader (libvulkan.so.1) found; install libvulkan1 or pass" \
            "--vulkan-deb libvulkan1_*.deb" >&2
        exit 1
    fi
    loader="$out-loader"
    rm -rf "$loader"
    mkdir -p "$loader"
    dpkg -x "$deb" "$loader"
    lib="$(dirname "$(find "$loader" -name 'libvulkan.so.1' -print -quit)")"
    export LD_LIBRARY_PATH="$lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    echo "gpu-bench: using the Vulkan loader unpacked from $deb ($lib)"
fi

rm -rf "$out"
mkdir -p "$out"
if command -v nvidia-smi >/dev/null; then
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.memory \
        --format=csv > "$out/nvidia-smi.csv" 2>&1 || true
fi
"$bin" bench --out "$out" "${bench_args[@]}"
tar -czf "$out.tar.gz" -C "$(dirname "$out")" "$(basename "$out")"
echo "gpu-bench: $(du -sh "$out.tar.gz" | cut -f1) in $out.tar.gz"

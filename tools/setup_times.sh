#!/usr/bin/env bash
# Times each step of the README's two commands (tools/run.sh, then tools/test.sh) on a
# fresh Debian 12 machine: a debootstrap chroot of bookworm holding only what the book's
# getting-started page asks for (gcc, g++, git, curl, CPython 3 with pip, sudo) and the
# host's rustup toolchain, with an empty cargo registry. Writes
# assets/results/setup-times/steps.csv (per step: wall and CPU seconds, the 1-minute load
# average as it started and ended) and meta.json; tools/results.py renders them into
# docs/src/getting-started.md. Run as root on a Debian host with debootstrap:
#
#   tools/setup_times.sh [--remove] [--logs DIR] CHROOT
#
# CHROOT is created (debootstrap --variant=minbase) when it does not exist; an existing
# one must be such a fresh chroot (none of tools/setup.sh's packages installed). A fresh
# clone of this checkout's HEAD goes to CHROOT/root/dvr. Each step's script is cut out
# of tools/run.sh and tools/test.sh (the lines from one step's first line to the next
# step's), so the steps run as the two commands run them. `bash tools/setup.sh --tests`
# is timed twice over: once with a stand-in `mdbook` on PATH (the Debian packages only),
# then as it is (the packages are there; it runs `cargo install mdbook`). Before each
# step it waits, up to 10 minutes, for the host's 1-minute load average to fall below
# 0.8. A step that fails is recorded with its exit status and the next one runs. The
# steps' output goes to DIR (default /tmp/setup-times-logs). Everything mounted under
# CHROOT is unmounted at the end; --remove then deletes CHROOT.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD

remove=false
logs=/tmp/setup-times-logs
while [ $# -gt 1 ]; do
  case "$1" in
    --remove) remove=true; shift ;;
    --logs) logs=$2; shift 2 ;;
    *) break ;;
  esac
done
[ $# -eq 1 ] || { echo "usage: tools/setup_times.sh [--remove] [--logs DIR] CHROOT" >&2; exit 2; }
[ "$(id -u)" -eq 0 ] || { echo "setup_times: run as root (debootstrap, chroot, mount)" >&2; exit 1; }
root=$(realpath -m "$1")
mkdir -p "$logs"
out=assets/results/setup-times
mkdir -p "$out"

say() { echo "setup_times: $*" >&2; }

mounted=()
unmount_all() {
  # Processes this run left inside the chroot (a test's server, say), by id.
  for p in /proc/[0-9]*; do
    if [ "$(readlink "$p/root" 2>/dev/null)" = "$root" ]; then
      say "ending process ${p#/proc/} left in the chroot"
      kill "${p#/proc/}" 2>/dev/null || true
    fi
  done
  sleep 1
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" || true
  done
  mounted=()
  if findmnt -rn -o TARGET | grep -q "^$root\(/\|$\)"; then
    say "still mounted under $root:"; findmnt -rn -o TARGET | grep "^$root\(/\|$\)" >&2
    return 1
  fi
}
trap unmount_all EXIT

bind() { # bind SRC DST [ro]
  mkdir -p "$2"
  mount --bind "$1" "$2"; mounted+=("$2")
  if [ "${3:-}" = ro ]; then mount -o remount,bind,ro "$2"; fi
}

# -------------------------------------------------------------- the fresh machine
base_packages=gcc,g++,git,ca-certificates,curl,python3,python3-pip,sudo,procps
if [ ! -e "$root/etc/debian_version" ]; then
  say "debootstrap of bookworm into $root"
  debootstrap --variant=minbase --include="$base_packages" bookworm "$root" \
    http://deb.debian.org/debian >"$logs/debootstrap.log" 2>&1
fi
if chroot "$root" dpkg-query -W -f='${Status}' libvulkan1 2>/dev/null | grep -q "install ok installed"; then
  say "$root is not fresh: libvulkan1 is installed"; exit 1
fi

cat >"$root/etc/apt/sources.list" <<'EOF'
deb http://deb.debian.org/debian bookworm main
deb http://deb.debian.org/debian bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$root/etc/resolv.conf"
# The host's own CA certificates, where it has any: a network that inspects TLS signs
# with them, and crates.io and PyPI are reached over TLS.
if compgen -G '/usr/local/share/ca-certificates/*.crt' >/dev/null; then
  cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
  chroot "$root" update-ca-certificates >"$logs/ca.log" 2>&1
fi
[ -s "$root/etc/hosts" ] || printf '127.0.0.1\tlocalhost\n::1\tlocalhost ip6-localhost ip6-loopback\n' >"$root/etc/hosts"
# No service that a package installs is started: the chroot shares the host's kernel
# and network.
printf '#!/bin/sh\nexit 101\n' >"$root/usr/sbin/policy-rc.d"
chmod +x "$root/usr/sbin/policy-rc.d"

mkdir -p "$root/proc" "$root/sys"
mount -t proc proc "$root/proc"; mounted+=("$root/proc")
mount -t sysfs -o ro sysfs "$root/sys"; mounted+=("$root/sys")
bind /dev "$root/dev"
bind /dev/pts "$root/dev/pts"
mkdir -p "$root/dev/shm"
mount -t tmpfs -o mode=1777 shm "$root/dev/shm"; mounted+=("$root/dev/shm")
chmod 1777 "$root/tmp"

# The host's rustup toolchains, read-only, behind an empty CARGO_HOME that holds only
# rustup's proxies: crates download as on a fresh machine.
rustup_home=${RUSTUP_HOME:-$HOME/.rustup}
cargo_bin=$(dirname "$(command -v rustup)")
bind "$rustup_home" "$root/root/.rustup" ro
rm -rf "$root/root/.cargo"
mkdir -p "$root/root/.cargo/bin"
for tool in rustup cargo rustc rustdoc rustfmt cargo-fmt cargo-clippy clippy-driver; do
  cp "$cargo_bin/rustup" "$root/root/.cargo/bin/$tool"
done

env_run=(chroot "$root" /usr/bin/env -i HOME=/root USER=root LOGNAME=root LANG=C.UTF-8
         TERM=dumb PATH=/root/.cargo/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin)

say "bringing the chroot's packages up to date (not timed)"
"${env_run[@]}" bash -c 'apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get upgrade -y -qq && apt-get clean' \
  >"$logs/upgrade.log" 2>&1

commit=$(git rev-parse --short HEAD)
rm -rf "$root/root/dvr"
git clone -q --no-hardlinks "$repo" "$root/root/dvr"
git -C "$root/root/dvr" checkout -q --detach "$(git rev-parse HEAD)"

# ---------------------------------------------------------------------- the steps
# cut FILE FIRST NEXT: FILE's lines from the one matching FIRST up to (not including)
# the one matching NEXT (or to the end when NEXT is empty); an error when FIRST or NEXT
# is not there, so a changed run.sh or test.sh stops this script rather than timing
# something else.
cut_lines() {
  awk -v first="$2" -v next_="$3" '
    $0 ~ first && !on && !done { on = 1; found = 1 }
    on && next_ != "" && $0 ~ next_ { on = 0; done = 1; ended = 1 }
    on { print }
    END { if (!found || (next_ != "" && !ended)) exit 1 }' "$1" \
    || { say "$1: no lines from /$2/ to /${3:-end}/"; exit 1; }
}

steps=$root/root/steps
rm -rf "$steps"; mkdir -p "$steps" "$steps/stand-in"
printf '#!/bin/sh\nexit 1\n' >"$steps/stand-in/mdbook"; chmod +x "$steps/stand-in/mdbook"
step_script() { # NAME PREFIX-LINE FILE FIRST NEXT
  { echo 'set -euo pipefail'; echo 'cd /root/dvr'; [ -z "$2" ] || echo "$2"
    cut_lines "$3" "$4" "$5"; } >"$steps/$1.sh"
}
R=tools/run.sh T=tools/test.sh
step_script setup "" $R '^bash tools/setup.sh$' '^cargo build --release$'
step_script build "" $R '^cargo build --release$' '^started='
step_script demo "" $R '^started=' ''
step_script setup-tests-apt 'export PATH=/root/steps/stand-in:$PATH' $T '^bash tools/setup.sh --tests$' '^cargo fmt'
step_script setup-tests-mdbook "" $T '^bash tools/setup.sh --tests$' '^cargo fmt'
step_script lint "" $T '^cargo fmt' '^DVR_VALIDATION=1 cargo test'
step_script test "" $T '^DVR_VALIDATION=1 cargo test' '^python3 tools/results.py --check'
step_script docs "" $T '^python3 tools/results.py --check' '^py='
step_script python "" $T '^py=' '^[(]cd target'
step_script pytest "" $T '^[(]cd target' ''

# command | step (its commands, comma-separated) | the script cut out above | what it does
plan=(
  "tools/run.sh|bash tools/setup.sh|setup|Debian packages: the Vulkan loader, lavapipe, the shader compilers, ffmpeg, a font"
  "tools/run.sh|cargo build --release|build|every crate downloaded and built, release profile"
  "tools/run.sh|target/release/dvr demo --out out/demo|demo|the main job on lavapipe, references included"
  "tools/test.sh|bash tools/setup.sh --tests|setup-tests-apt|Debian packages: the validation layers, Xvfb, Chromium, python3-venv, iproute2"
  "tools/test.sh|bash tools/setup.sh --tests|setup-tests-mdbook|mdBook: cargo install mdbook, from crates.io"
  "tools/test.sh|cargo fmt --check, cargo clippy|lint|formatting; clippy checks the workspace, dev profile"
  "tools/test.sh|DVR_VALIDATION=1 cargo test --workspace|test|the tests' build and run, validation layer on"
  "tools/test.sh|tools/results.py --check, mdbook build docs, cargo doc|docs|the book and the Rust API reference"
  "tools/test.sh|python3 -m venv, pip install, maturin build, pdoc, tools/check_docs.py|python|the test packages downloaded into target/py, the wheel built, the Python reference, the book's links"
  "tools/test.sh|pytest python/tests|pytest|the Python tests against the installed wheel"
)

load1() { cut -d' ' -f1 /proc/loadavg; }
wait_load() {
  local waited=0
  while awk -v l="$(load1)" 'BEGIN { exit !(l >= 0.8) }' && [ $waited -lt 600 ]; do
    sleep 10; waited=$((waited + 10))
  done
  echo $waited
}

csv=$out/steps.csv
echo "command,step,what,wall_s,cpu_s,user_s,sys_s,load_start,load_end,waited_s,exit,note" >"$csv.tmp"
total_started=$(date +%s)
for entry in "${plan[@]}"; do
  IFS='|' read -r command step script what <<<"$entry"
  waited=$(wait_load)
  l0=$(load1)
  say "$step (load $l0, waited ${waited} s)"
  tf=$(mktemp)
  set +e
  /usr/bin/time -f '%e %U %S' -o "$tf" "${env_run[@]}" bash "/root/steps/$script.sh" \
    >"$logs/$script.log" 2>&1 </dev/null
  rc=$?
  set -e
  l1=$(load1)
  read -r wall user sys < <(tail -n 1 "$tf")
  rm -f "$tf"
  cpu=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
  note=""
  [ $rc -eq 0 ] || note="failed (exit $rc)"
  say "  $wall s wall, $cpu s CPU, exit $rc"
  printf '%s,"%s","%s",%s,%s,%s,%s,%s,%s,%s,%s,"%s"\n' "$command" "$step" "$what" "$wall" "$cpu" \
    "$user" "$sys" "$l0" "$l1" "$waited" "$rc" "$note" >>"$csv.tmp"
done
mv "$csv.tmp" "$csv"

# ----------------------------------------------------------------------- meta.json
debian=$(cat "$root/etc/debian_version")
rustc=$("${env_run[@]}" rustc --version)
cargo_v=$("${env_run[@]}" cargo --version)
cpu_model=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
mem_gib=$(awk '/MemTotal/ { printf "%.0f", $2 / 1048576 }' /proc/meminfo)
device=$(grep -o "llvmpipe ([^)]*)" "$root/root/dvr/out/demo/index.html" 2>/dev/null | head -n 1 || true)
python3 - "$out/meta.json" <<EOF
import json, sys
meta = {
    "set": "setup-times",
    "command": "tools/setup_times.sh (a fresh debootstrap chroot of Debian 12)",
    "commit": "$commit",
    "date": "$(date +%F)",
    "machine": "$(nproc) cores, $cpu_model, $mem_gib GiB; Debian $debian (a debootstrap chroot on a Debian 12 host)"
               + ("; Vulkan device: $device" if "$device" else ""),
    "nproc": $(nproc),
    "memory_gib": $mem_gib,
    "debian": "$debian",
    "rustc": "$rustc",
    "cargo": "$cargo_v",
    "base_packages": "$base_packages".split(","),
    "wall_s": $(($(date +%s) - total_started)),
    "load_average_at_end": [float(x) for x in open("/proc/loadavg").read().split()[:3]],
}
with open(sys.argv[1], "w") as f:
    json.dump(meta, f, indent=2)
    f.write("\n")
EOF
say "wrote $csv and $out/meta.json"

unmount_all
trap - EXIT
if $remove; then
  rm -rf --one-file-system "$root"
  say "removed $root"
fi

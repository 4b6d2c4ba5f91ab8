#!/usr/bin/env bash
# Runs one measured set and keeps what the run wrote: its CSVs (or the profiler's JSON),
# not its images, under assets/results/<set>/, with meta.json beside them (the command,
# the commit, the machine, the date and the wall time). tools/results.py renders the
# book's results pages and README's headline table from those files.
#
#   tools/measure.sh SET [SET ...]     SET: demo static development validation paper
#                                           suite cost rae cut-cost labels-cost
#                                           channels-cost interaction mechanisms
#
# The cut, channel-and-time and label-map scenes the results page shows by kind are the
# development and validation sets' own: `mechanisms` and `validation` measure them.
#
# Needs a release build (cargo build --release). The eval sets also add Intel OIDN with
# tools/oidn_eval.py, which needs a Python with the dvr package, pyoidn, numpy, OpenEXR
# and pillow: PY=/path/to/python (default .venv/bin/python; see the book's evaluation
# page). References are cached under out/<set>, so a rerun renders only the methods.
# Long: on a 2-core CPU with lavapipe the validation set's references take over an hour,
# the suite's about an hour, the paper set's about half an hour.
set -euo pipefail
cd "$(dirname "$0")/.."
dvr=${DVR_BIN:-target/release/dvr}
py=${PY:-.venv/bin/python}
[ -x "$dvr" ] || { echo "measure: $dvr is missing: cargo build --release" >&2; exit 1; }

commit=$(git rev-parse --short HEAD)
[ -z "$(git status --porcelain -- src engine shaders Cargo.lock)" ] || commit="$commit+local"
machine="$(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -1), Debian $(cat /etc/debian_version 2>/dev/null || echo '?')"

# meta SET OUTDIR SECONDS COMMAND...: writes assets/results/SET/meta.json.
meta() {
  local set=$1 out=$2 secs=$3
  shift 3
  python3 - "$set" "$out" "$secs" "$commit" "$machine" "$*" <<'EOF'
import glob, json, sys, datetime
set_, out, secs, commit, machine, command = sys.argv[1:]
device = ""
for f in sorted(glob.glob(f"{out}/*/result.json")) + sorted(glob.glob(f"{out}/*.json")):
    try:
        d = json.load(open(f))
    except Exception:
        continue
    device = d.get("device") or (d.get("result") or {}).get("device") or ""
    if device:
        break
meta = {
    "set": set_,
    "command": command,
    "commit": commit,
    "date": datetime.date.today().isoformat(),
    "machine": machine + (f"; Vulkan device: {device}" if device else ""),
    "wall_s": round(float(secs), 1),
    # What else ran: the 1-, 5- and 15-minute load averages as the run ended (a wall
    # time from a busy machine is not one from an idle one).
    "load_average_at_end": [float(x) for x in open("/proc/loadavg").read().split()[:3]],
}
json.dump(meta, open(f"assets/results/{set_}/meta.json", "w"), indent=2, ensure_ascii=False)
open(f"assets/results/{set_}/meta.json", "a").write("\n")
EOF
}

# keep SET OUTDIR [SUBDIR]: copies the eval's CSVs.
keep() {
  local dest="assets/results/$1${3:+/$3}"
  mkdir -p "$dest"
  cp "$2/summary.csv" "$dest/summary.csv"
  [ -z "${KEEP_METRICS:-}" ] || cp "$2/metrics.csv" "$dest/metrics.csv"
  [ ! -f "$2/oidn_ms.csv" ] || cp "$2/oidn_ms.csv" "$dest/oidn_ms.csv"
}

oidn() { "$py" tools/oidn_eval.py "$1"; }

# share_references SRC DST: DST/<scene>/reference links to SRC's, so a run into DST at
# another --spp reuses SRC's references (they do not depend on --spp) and leaves SRC's
# frames as the run that made them wrote them.
share_references() {
  local d scene
  for d in "$1"/*/reference; do
    [ -d "$d" ] || continue
    scene=$(basename "$(dirname "$d")")
    mkdir -p "$2/$scene"
    ln -sfn "$PWD/$d" "$2/$scene/reference"
  done
}

timed() { # timed CMD...: runs it, leaves its wall seconds in $secs
  local t0
  t0=$(date +%s.%N)
  "$@"
  secs=$(echo "$(date +%s.%N) - $t0" | bc)
}

for set in "$@"; do
  out=out/$set
  mkdir -p "assets/results/$set"
  case $set in
    demo)
      rm -rf "$out"
      timed "$dvr" demo --out "$out"
      KEEP_METRICS=1 keep demo "$out"
      meta demo "$out" "$secs" "dvr demo --out $out (a fresh folder: references included)"
      ;;
    static)
      args=(--scene static --size 128x128 --ref-spp 256 --aux --denoiser none,taa,svgf,ours)
      timed "$dvr" eval "${args[@]}" --out "$out"
      oidn "$out"
      KEEP_METRICS=1 keep static "$out"
      meta static "$out" "$secs" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out"
      ;;
    development)
      args=(--scene development --frames 48 --size 64x64 --ref-spp 1024 --aux
        --denoiser none,taa,svgf,ours,ours-no-gradient,ours-no-lag,ours-no-prior,ours-no-atrous,ours-no-feedback,ours-no-young,wrls-paper,rae)
      timed "$dvr" eval "${args[@]}" --out "$out"
      oidn "$out"
      keep development "$out"
      meta development "$out" "$secs" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out"
      ;;
    validation)
      # At 2 spp with every method; then the methods of the speed-against-accuracy chart
      # at 1 and 4 spp, each into its own folder on the same references (share_references).
      args=(--scene validation --size 128x128 --ref-spp 256 --aux
        --denoiser none,taa,svgf,ours,ours-no-gradient,ours-no-lag,ours-no-prior,ours-no-atrous,ours-no-feedback,ours-no-young,rae)
      timed "$dvr" eval "${args[@]}" --out "$out"
      total=$secs
      oidn "$out"
      KEEP_METRICS=1 keep validation "$out"
      for spp in 1 4; do
        argsn=(--scene validation --size 128x128 --ref-spp 256 --spp $spp --aux --denoiser none,taa,svgf,ours,rae)
        share_references "$out" "$out-spp$spp"
        timed "$dvr" eval "${argsn[@]}" --out "$out-spp$spp"
        total=$(echo "$total + $secs" | bc)
        oidn "$out-spp$spp"
        KEEP_METRICS=1 keep validation "$out-spp$spp" spp$spp
      done
      meta validation "$out" "$total" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out; for spp in 1 4: dvr eval --scene validation --size 128x128 --ref-spp 256 --spp \$spp --aux --denoiser none,taa,svgf,ours,rae --out $out-spp\$spp && tools/oidn_eval.py $out-spp\$spp"
      ;;
    suite)
      args=(--scene suite --frames 48 --size 64x64 --ref-spp 1024 --aux
        --denoiser none,taa,svgf,ours,ours-no-gradient,ours-no-lag,ours-no-prior,ours-no-atrous,ours-no-feedback,ours-no-young,wrls-paper,rls-paper,wrls,rls,wrls-nf,rls-nf,rae)
      timed "$dvr" eval "${args[@]}" --out "$out"
      oidn "$out"
      keep suite "$out"
      meta suite "$out" "$secs" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out"
      ;;
    rae)
      # The networks against the temporal filters on short clips (12 frames, at the
      # networks' training size), where a network is not behind filters still converging.
      args=(--scene suite --frames 12 --size 64x64 --spp 2 --ref-spp 1024
        --denoiser none,svgf,ours,rae,rae-phantom,rae-mri,rae-fp16)
      timed "$dvr" eval "${args[@]}" --out "$out"
      keep rae "$out"
      meta rae "$out" "$secs" "dvr eval ${args[*]} --out $out"
      ;;
    paper)
      # One folder per noise level (out/paper-sppN), all on out/paper-spp1's references
      # (share_references: they do not depend on --spp), so each level's frames stay.
      total=0
      for spp in 1 2 4; do
        args=(--scene paper --size 64x64 --spp $spp
          --denoiser none,taa,svgf,wrls-paper,rls-paper,wrls,rls,rae,ours)
        [ "$spp" = 1 ] || share_references "$out-spp1" "$out-spp$spp"
        timed "$dvr" eval "${args[@]}" --out "$out-spp$spp"
        total=$(echo "$total + $secs" | bc)
        oidn "$out-spp$spp"
        keep paper "$out-spp$spp" "spp$spp"
      done
      meta paper "$out-spp1" "$total" "for spp in 1 2 4: dvr eval --scene paper --size 64x64 --spp \$spp --denoiser none,taa,svgf,wrls-paper,rls-paper,wrls,rls,rae,ours --out $out-spp\$spp && tools/oidn_eval.py $out-spp\$spp"
      ;;
    cost)
      mkdir -p "$out"
      secs=0
      for scene in mri/point-light phantom/orbit; do
        name=${scene/\//-}
        timed "$dvr" profile --scene "$scene" --frames 30 --size 256x256 --denoiser ours,svgf --json "$out/$name.json"
        cp "$out/$name.json" "assets/results/cost/$name.json"
      done
      meta cost "$out" "$secs" "dvr profile --scene S --frames 30 --size 256x256 --denoiser ours,svgf --json out/cost/S.json, S = mri/point-light, phantom/orbit"
      ;;
    cut-cost)
      # The same view with and without a plane that removes half the volume, profiled
      # alternately (two runs each), so the machine's drift falls on both.
      mkdir -p "$out"
      "$dvr" scenes --dump phantom/orbit > "$out/plain.toml"
      { cat "$out/plain.toml"; printf '\n[[clip]]\npoint = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\n'; } > "$out/half.toml"
      t0=$(date +%s.%N)
      for run in 1 2; do
        for cut in plain half; do
          "$dvr" profile --scene "$out/$cut.toml" --frames 20 --size 256x256 --denoiser ours \
            --json "$out/$cut-$run.json" >/dev/null
        done
      done
      secs=$(echo "$(date +%s.%N) - $t0" | bc)
      python3 - "$out" <<'EOF2'
import csv, json, sys
out = sys.argv[1]
with open("assets/results/cut-cost/profile.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["scene", "cut", "run", "path_trace_ms", "frame_ms"])
    for run in (1, 2):
        for cut, what in (("plain", "none"), ("half", "x < 0 removed")):
            p = json.load(open(f"{out}/{cut}-{run}.json"))
            pt = next(x["median_ms"] for x in p["passes"] if x["pass"] == "path_trace")
            w.writerow(["phantom/orbit", what, run, f"{pt:.3f}", f"{p['total']['median_ms']:.3f}"])
EOF2
      meta cut-cost "$out" "$secs" "dvr profile --scene S --frames 20 --size 256x256 --denoiser ours, S = phantom/orbit with and without [[clip]] point [0,0,0] normal [1,0,0], alternating, two runs each"
      ;;
    channels-cost)
      # What the channels of a medium cost the path tracer: the MNI T1 under the layered
      # (semi-transparent) TF as one field, and the same file as 2 and 4 channels in two
      # layouts, each the same medium as the one field: "hidden", every channel but the
      # first hidden; "split", every channel shown, white, under the TF with its opacity
      # divided among them (their extinctions sum to the one field's). Profiled
      # alternately, three runs each.
      mkdir -p "$out"
      t1="$PWD/assets/volumes/mni152_t1.nii.gz"
      view='[transfer]\na = "mri-layered"\n\n[camera]\nposition = [0.45, 1.5, 0.35]\n\n[[light]]\nkind = "point"\nposition = [-1.4, 0.0, 0.8]\nintensity = 20.0\n\n[[light]]\nkind = "environment"\nintensity = 0.25\n'
      for n in 2 4; do
        python3 - "$n" > "$out/mri-layered-$n.toml" <<'EOF1'
import re, sys
n = int(sys.argv[1])
tf = open("assets/transfer/mri-layered.toml").read()
tf = re.sub(r'^name = "mri-layered"', f'name = "mri-layered-{n}th"', tf, flags=re.M)
print(re.sub(r"^opacity = ([0-9.]+)", lambda m: f"opacity = {float(m[1]) / n!r}", tf, flags=re.M))
EOF1
      done
      files() { for _ in $(seq "$1"); do printf '"%s",' "$t1"; done; }
      layouts=(1-one 2-hidden 2-split 4-hidden 4-split)
      for l in "${layouts[@]}"; do
        n=${l%%-*} layout=${l#*-}
        {
          if [ "$layout" = one ]; then
            printf '[volume]\nfile = "%s"\ndensity_scale = 150.0\n\n' "$t1"
          else
            printf '[volume]\nfiles = [%s]\ndensity_scale = 150.0\n\n' "$(files "$n")"
            for c in $(seq "$n"); do
              if [ "$layout" = hidden ]; then
                printf '[[channel]]\nvisible = %s\n\n' "$([ "$c" = 1 ] && echo true || echo false)"
              else
                printf '[[channel]]\ntransfer = "mri-layered-%s.toml"\ncolour = [1.0, 1.0, 1.0]\n\n' "$n"
              fi
            done
          fi
          printf '%b' "$view"
        } > "$out/channels-$l.toml"
      done
      t0=$(date +%s.%N)
      for run in 1 2 3; do
        for l in "${layouts[@]}"; do
          "$dvr" profile --scene "$out/channels-$l.toml" --frames 24 --size 256x256 --denoiser ours \
            --json "$out/channels-$l-$run.json" >/dev/null
        done
      done
      secs=$(echo "$(date +%s.%N) - $t0" | bc)
      python3 - "$out" "${layouts[@]}" <<'EOF2'
import csv, json, sys
out, layouts = sys.argv[1], sys.argv[2:]
with open("assets/results/channels-cost/profile.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["scene", "channels", "layout", "run", "path_trace_ms", "frame_ms"])
    for run in (1, 2, 3):
        for l in layouts:
            n, layout = l.split("-")
            p = json.load(open(f"{out}/channels-{l}-{run}.json"))
            pt = next(x["median_ms"] for x in p["passes"] if x["pass"] == "path_trace")
            w.writerow(["mni152_t1 / mri-layered", n, layout, run, f"{pt:.3f}",
                        f"{p['total']['median_ms']:.3f}"])
EOF2
      meta channels-cost "$out" "$secs" "dvr profile --scene S --frames 24 --size 256x256 --denoiser ours, S = the MNI T1 under mri-layered as one field, and as [volume] files = the same file 2 and 4 times, hidden (every channel but the first hidden) and split (every channel shown, white, under mri-layered with its opacity divided by the channel count), alternating, three runs each"
      ;;
    interaction)
      # The frozen interaction set (drags, a zoom, a window drag, a light drag, cold
      # opens) with the development and validation cut scenes, every method ours is
      # judged against, and OIDN.
      cuts=assets/scenes/development/mri-clip-sweep.toml,assets/scenes/development/phantom-clip-toggle.toml,assets/scenes/development/phantom-crop-shrink.toml,assets/scenes/validation/cloud-oblique-clip-light.toml
      args=(--scene "interaction,$cuts" --size 128x128 --ref-spp 256 --aux
        --denoiser none,taa,svgf,ours,rae)
      timed "$dvr" eval "${args[@]}" --out "$out"
      oidn "$out"
      KEEP_METRICS=1 keep interaction "$out"
      meta interaction "$out" "$secs" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out"
      ;;
    mechanisms)
      # Each of ours' mechanisms switched off alone, on the development set as ours is
      # judged (128×128, 48 frames, 256-spp references): the stage ablations beside every
      # method ours is judged against, then ours with each parameter-borne mechanism off
      # (DVR_OURS), on the same references and the same noisy frames.
      args=(--scene development --frames 48 --size 128x128 --ref-spp 256 --aux
        --denoiser none,taa,svgf,rae,ours,ours-no-gradient,ours-no-lag,ours-no-prior,ours-no-atrous,ours-no-feedback,ours-no-young)
      timed "$dvr" eval "${args[@]}" --out "$out"
      total=$secs
      oidn "$out"
      KEEP_METRICS=1 keep mechanisms "$out"
      overrides=("no-jump|jump_z=1000" "no-motion-q|motion_q=0"
        "no-change-q|change_q=0" "no-keep|keep=0")
      printf 'run,override\n' > "assets/results/mechanisms/overrides.csv"
      for o in "${overrides[@]}"; do
        IFS='|' read -r name spec <<< "$o"
        share_references "$out" "$out-$name"
        # --no-baseline: these runs' scores are read, not the accumulation curve.
        DVR_OURS=$spec timed "$dvr" eval --scene development --frames 48 --size 128x128 \
          --ref-spp 256 --denoiser ours --no-baseline --out "$out-$name"
        total=$(echo "$total + $secs" | bc)
        cp "$out-$name/metrics.csv" "assets/results/mechanisms/$name.csv"
        printf '%s,%s\n' "$name" "$spec" >> "assets/results/mechanisms/overrides.csv"
      done
      meta mechanisms "$out" "$total" "dvr eval ${args[*]} --out $out && tools/oidn_eval.py $out; for each run,override of overrides.csv: DVR_OURS=override dvr eval --scene development --frames 48 --size 128x128 --ref-spp 256 --denoiser ours --no-baseline --out $out-run"
      ;;
    labels-cost)
      # Two heads under opaque TFs, each labelled everywhere it has tissue (label 0 is
      # air): the phantom (scalp, skull, brain, ventricles, vessels) and the MNI head
      # (white matter, grey matter, the rest of the brain). Each view without a label
      # map, with every label shown (tint), and with labels hidden from the outside in
      # (what lies beneath shows) until every one is; profiled alternately (two runs
      # each), so the machine's drift falls on all. A view is `key|hidden values|what`.
      mkdir -p "$out"
      t0=$(date +%s.%N)
      views_phantom=("outer|1 2|scalp and skull hidden" "all|1 2 3 4 5|every label hidden")
      views_mri=("rest|3|rest of the brain hidden" "outer|2 3|grey matter and the rest hidden"
        "all|1 2 3|every label hidden")
      : > "$out/views.tsv"
      for scene in phantom/orbit mri/point-light; do
        name=${scene%%/*}
        "$dvr" scenes --dump "$scene" > "$out/$name-none.toml"
        # Shown: every label of the built-in table visible, whatever its default.
        { cat "$out/$name-none.toml"; printf '\n[labels]\nbuiltin = "%s"\n' "$name"; } > "$out/$name-shown.toml"
        [ "$name" = mri ] && printf '\n[[label]]\nvalue = 3\nvisible = true\n' >> "$out/$name-shown.toml"
        printf '%s\tnone\tno label map\n%s\tshown\tevery label shown (tint)\n' "$scene" "$scene" >> "$out/views.tsv"
        views="views_$name[@]"
        keys=(none shown)
        for view in "${!views}"; do
          IFS='|' read -r key hidden what <<< "$view"
          keys+=("$key")
          { cat "$out/$name-none.toml"; printf '\n[labels]\nbuiltin = "%s"\n' "$name"; } > "$out/$name-$key.toml"
          for v in 1 2 3 4 5; do
            case " $hidden " in *" $v "*) shown=false ;; *) shown=true ;; esac
            [ "$name" = mri ] && [ "$v" -gt 3 ] && continue
            printf '\n[[label]]\nvalue = %s\nvisible = %s\n' "$v" "$shown" >> "$out/$name-$key.toml"
          done
          printf '%s\t%s\t%s\n' "$scene" "$key" "$what" >> "$out/views.tsv"
        done
        if [ "$name" = mri ]; then
          # What the grey-matter-hidden view shows, as data: the T1 with its grey-matter and
          # rest voxels set to 0, no label map (its rays go as deep; no label is read).
          "$py" - "$out/mri-white.nii.gz" <<'EOF3'
import sys
import nibabel as nib
import numpy as np
t1 = nib.load("assets/volumes/mni152_t1.nii.gz")
labels = np.asarray(nib.load("assets/volumes/mni152_labels.nii.gz").dataobj)
data = np.asarray(t1.dataobj).copy()
data[(labels == 2) | (labels == 3)] = 0
nib.save(nib.Nifti1Image(data, t1.affine, t1.header), sys.argv[1])
EOF3
          sed "0,/^builtin = \"mri\"\$/s||file = \"$PWD/$out/mri-white.nii.gz\"|" "$out/mri-none.toml" > "$out/mri-data.toml"
          # The same data with the label map, every label shown: what that tissue costs
          # through the label path, against which hiding is judged.
          { cat "$out/mri-data.toml"
            printf '\n[labels]\nfile = "%s"\ntable = "%s"\n' "$PWD/assets/volumes/mni152_labels.nii.gz" \
              "$PWD/assets/volumes/mni152_labels.label"
            printf '\n[[label]]\nvalue = 3\nvisible = true\n'; } > "$out/mri-datashown.toml"
          keys+=(data datashown)
          printf '%s\tdata\tgrey matter and the rest removed from the data (no label map)\n' "$scene" >> "$out/views.tsv"
          printf '%s\tdatashown\tgrey matter and the rest removed from the data, every label shown\n' "$scene" >> "$out/views.tsv"
        fi
        for run in 1 2 3; do
          for key in "${keys[@]}"; do
            "$dvr" profile --scene "$out/$name-$key.toml" --frames 20 --size 256x256 --denoiser ours \
              --json "$out/$name-$key-$run.json" >/dev/null
          done
        done
      done
      secs=$(echo "$(date +%s.%N) - $t0" | bc)
      python3 - "$out" <<'EOF2'
import csv, json, sys
out = sys.argv[1]
views = [line.rstrip("\n").split("\t") for line in open(f"{out}/views.tsv")]
with open("assets/results/labels-cost/profile.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["scene", "labels", "run", "path_trace_ms", "frame_ms"])
    for scene in dict.fromkeys(v[0] for v in views):
        name = scene.split("/")[0]
        for run in (1, 2, 3):
            for _, key, what in (v for v in views if v[0] == scene):
                p = json.load(open(f"{out}/{name}-{key}-{run}.json"))
                pt = next(x["median_ms"] for x in p["passes"] if x["pass"] == "path_trace")
                w.writerow([scene, what, run, f"{pt:.3f}", f"{p['total']['median_ms']:.3f}"])
EOF2
      meta labels-cost "$out" "$secs" "dvr profile --scene S --frames 20 --size 256x256 --denoiser ours, S = phantom/orbit and mri/point-light without a label map, with [labels] builtin = the dataset and every label shown, with labels hidden from the outside in until every one is, and (mri) the T1 with its grey matter and rest set to 0 in the data, without the label map and with it (every label shown), alternating, three runs each"
      ;;
    *)
      echo "measure: unknown set '$set' (demo static development validation paper suite cost rae cuts cut-cost labels labels-cost channels-cost statmap)" >&2
      exit 2
      ;;
  esac
  echo "measure: $set done in ${secs%.*} s -> assets/results/$set/"
done

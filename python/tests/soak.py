"""Long live sessions with random edits: a Python renderer, the explorer under Xvfb and
the notebook viewer. Each returns one row of figures: frames, time, resident memory and
device memory after a warm-up (every kind of edit made once) and at the end, and the
validation layer's messages. test_soak.py runs short versions; tools/soak.py the long
ones, writing assets/results/soak/soak.csv.

A session passes when its resident memory at the end is within 5 % of the figure after
the warm-up, its device memory (the allocator's counters) at the end is no more than
after the warm-up, measured both times in the same state (size, denoisers shown: what
the device holds follows what the last frames drew, so only a leak makes it grow), and
the validation layer said nothing.
"""

import os
import pathlib
import random
import re
import shutil
import subprocess
import tempfile
import time

import dvr

RSS_GROWTH = 0.05


def rss_mib():
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith("VmRSS")) / 1024


def passed(row):
    return (
        row["rss_growth"] <= RSS_GROWTH
        and row["gpu_allocated_end_mib"] <= row["gpu_allocated_warm_mib"] + 1e-6
        and row["validation_messages"] == 0
    )


def _row(what, frames, seconds, rss, gpu, messages):
    """`rss`, `gpu`: resident and device memory (MiB) after the warm-up and at the end."""
    (rss_warm, rss_end), (gpu_warm, gpu_end) = rss, gpu
    return {
        "session": what,
        "frames": frames,
        "seconds": round(seconds, 1),
        "rss_warm_mib": round(rss_warm, 1),
        "rss_end_mib": round(rss_end, 1),
        "rss_growth": round((rss_end - rss_warm) / rss_warm, 4),
        "gpu_allocated_warm_mib": round(gpu_warm, 3),
        "gpu_allocated_end_mib": round(gpu_end, 3),
        "validation_messages": messages,
    }


def python_session(renders, seed=0, size=(32, 32)):
    """A live renderer rendered `renders` times with a random edit before most renders:
    camera (orbit, pan, zoom, set), lights, TF, settings, denoisers and split pairs, size,
    clip planes and the crop box. The warm-up is one pass through every kind of edit."""
    rng = random.Random(seed)
    messages = dvr._native.validation_messages()
    r = dvr.Renderer(dvr.Scene.builtin("phantom/orbit"), size=size, denoisers=["ours"])
    presets = ["phantom-opaque", "phantom-layered", "phantom-vessels"]
    pairs = [["ours"], ["svgf"], ["ours", "svgf"], ["taa", "ours"]]

    def edit(kind):
        if kind == "orbit":
            r.orbit(rng.uniform(-40, 40), rng.uniform(-20, 20))
        elif kind == "pan":
            r.pan(rng.uniform(-5, 5), rng.uniform(-5, 5))
        elif kind == "zoom":
            r.zoom(rng.choice([-1, 1]) * rng.uniform(0.1, 1.0))
        elif kind == "reset":
            r.reset_camera()
        elif kind == "light":
            r.lights[0].update(intensity=rng.uniform(5, 40), position=(rng.uniform(-1, 1), 1.1, rng.uniform(0.2, 1.2)))
        elif kind == "tf":
            r.tf = rng.choice(presets)
        elif kind == "spp":
            r.settings.spp = rng.choice([1, 2])
        elif kind == "denoisers":
            r.denoisers = rng.choice(pairs)
        elif kind == "size":
            r.size = rng.choice([size, (size[0] // 2, size[1] // 2)])
        elif kind == "clip":
            if len(r.clip) >= 6 or (len(r.clip) and rng.random() < 0.5):
                del r.clip[0]
            else:
                r.clip.append(dvr.ClipPlane((0.0, 0.0, rng.uniform(-0.3, 0.3)), (0.0, rng.uniform(-1, 1), 1.0)))
        elif kind == "crop":
            r.crop = None if r.crop is not None else dvr.CropBox(max=(0.5, 0.5, rng.uniform(-0.2, 0.5)))

    kinds = ["orbit", "pan", "zoom", "reset", "light", "tf", "spp", "denoisers", "size", "clip", "crop"]
    started = time.perf_counter()
    for kind in kinds:  # the warm-up: every kind once, and every denoiser pair
        edit(kind)
        r.render()
    for pair in pairs:
        r.denoisers = pair
        r.render()
    def settle():
        """The state both figures are taken in: the first size, ours and svgf, rendered
        for more frames than the device keeps in flight."""
        r.size, r.denoisers = size, pairs[2]
        for _ in range(4):
            r.render()
        return rss_mib(), r.gpu_memory()["allocated"] / 2**20

    rss_warm, gpu_warm = settle()
    for _ in range(renders):
        if rng.random() < 0.7:
            edit(rng.choice(kinds))
        r.render()
    rss_end, gpu_end = settle()
    r.close()
    return _row(
        "python live renderer", renders, time.perf_counter() - started, (rss_warm, rss_end),
        (gpu_warm, gpu_end), dvr._native.validation_messages() - messages,
    )


def series_session(renders, seed=0, size=(32, 32)):
    """A 4D series (the beating shell, 24 time points) played for `renders` frames at a
    fractional time that moves on each frame (two time points interpolated, the next read
    ahead), with a random jump now and then; the warm-up plays one whole beat."""
    rng = random.Random(seed)
    messages = dvr._native.validation_messages()
    scene = dvr.Scene.load(str(pathlib.Path(__file__).resolve().parents[2] / "assets/scenes/development/shell-beat-still.toml"))
    r = dvr.Renderer(scene, size=size, denoisers=["ours"])
    last = r.times - 1
    started = time.perf_counter()
    t = 0.0

    def step():
        nonlocal t
        t = rng.uniform(0, last) if rng.random() < 0.02 else (t + 0.37) % last
        r.time = t
        r.render()

    for _ in range(int(last / 0.37) + 1):
        step()
    rss_warm, gpu_warm = rss_mib(), r.gpu_memory()["allocated"] / 2**20
    for _ in range(renders):
        step()
    rss_end, gpu_end = rss_mib(), r.gpu_memory()["allocated"] / 2**20
    r.close()
    return _row(
        "4D series played", renders, time.perf_counter() - started, (rss_warm, rss_end),
        (gpu_warm, gpu_end), dvr._native.validation_messages() - messages,
    )


def explorer_script(frames, seed=0, size=64):
    """A --script of random edits over `frames` frames: the first 60 frames make every
    kind once (the warm-up), the last 20 return to the first size and denoiser."""
    rng = random.Random(seed)
    warm = [
        "orbit:30,5@2", "pan:4,-3@4", "zoom:1@6", "key:r@8", "tf:phantom-opaque@10", "denoiser:svgf@12",
        "split:taa@14", "split:off@16", f"size:{size // 2}x{size // 2}@18", f"size:{size}x{size}@22",
        "clip:add@24", "clip:offset:0.05@26", "crop:on@28", "crop:max:0.5,0.5,0.1@30", "key:c@32", "key:c@34",
        "denoiser:ours@36", "key:f@38",
    ]
    choices = [
        lambda: f"orbit:{rng.uniform(-30, 30):.1f},{rng.uniform(-10, 10):.1f}",
        lambda: f"pan:{rng.uniform(-4, 4):.1f},{rng.uniform(-4, 4):.1f}",
        lambda: f"zoom:{rng.uniform(-1, 1):.2f}",
        lambda: "key:r",
        lambda: f"tf:{rng.choice(['phantom-opaque', 'phantom-layered', 'phantom-vessels'])}",
        lambda: f"denoiser:{rng.choice(['ours', 'svgf', 'taa'])}",
        lambda: f"split:{rng.choice(['off', 'taa', 'svgf'])}",
        lambda: f"size:{rng.choice([size, size // 2])}x{rng.choice([size, size // 2])}",
        lambda: rng.choice(["clip:flip", f"clip:offset:{rng.uniform(-0.1, 0.1):.3f}", "key:c"]),
        lambda: rng.choice(["crop:on", "crop:off", f"crop:max:0.5,0.5,{rng.uniform(-0.2, 0.5):.2f}"]),
    ]
    events = list(warm)
    for f in range(60, frames - 20, 3):
        if rng.random() < 0.6:
            events.append(f"{rng.choice(choices)()}@{f}")
    events += [f"size:{size}x{size}@{frames - 20}", f"denoiser:ours@{frames - 20}", f"split:off@{frames - 20}"]
    return ";".join(events)


def explorer_session(dvr_bin, frames, seed=0, size=64):
    """`dvr explore` under its own Xvfb for `frames` frames of random edits; its device and
    resident memory after frame 40 and after the last, from its summary."""
    xvfb = shutil.which("Xvfb")
    if not xvfb:
        raise RuntimeError("Xvfb is not installed (tools/setup.sh installs it)")
    display = f":{400 + os.getpid() % 500}"
    x = subprocess.Popen([xvfb, display, "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 10
        while not pathlib.Path(f"/tmp/.X11-unix/X{display[1:]}").exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        env = dict(os.environ, DISPLAY=display, DVR_VALIDATION="1")
        with tempfile.TemporaryFile(mode="w+") as log:
            started = time.perf_counter()
            p = subprocess.Popen(
                [dvr_bin, "explore", "--scene", "phantom/orbit", "--size", f"{size}x{size}", "--frames", str(frames),
                 "--no-vsync", "--moving-ms", "0", "--script", explorer_script(frames, seed, size)],
                stdout=log, stderr=subprocess.STDOUT, env=env,
            )
            p.wait()
            seconds = time.perf_counter() - started
            log.seek(0)
            out = log.read()
        if p.returncode != 0:
            raise RuntimeError(f"dvr explore exited with {p.returncode}:\n{out[-3000:]}")
        m = re.search(r"GPU memory ([\d.]+) MiB allocated after frame \d+, ([\d.]+) MiB after the last; "
                      r"resident memory ([\d.]+) MiB after frame \d+, ([\d.]+) MiB after the last", out)
        if not m:
            raise RuntimeError(f"no memory figures in the explorer's summary:\n{out[-3000:]}")
        messages = len(re.findall(r"validation", out, re.IGNORECASE))
        gpu_warm, gpu_end, rss_warm, rss_end = map(float, m.groups())
        return _row("explorer under Xvfb", frames, seconds, (rss_warm, rss_end), (gpu_warm, gpu_end), messages)
    finally:
        x.kill()
        x.wait()


def notebook_session(lab, browser, seconds, size=64):
    """dvr.Viewer left refining in a real JupyterLab for `seconds`: the kernel's resident
    memory and device memory after a warm-up and at the end."""
    from lab import Notebook, write_notebook

    name = f"soak{os.getpid()}.ipynb"
    write_notebook(lab.root / name, [
        f"import dvr, os\nv = dvr.Viewer('phantom/orbit', size=({size}, {size}), denoisers=['ours'])\nv",
        "import time\ntime.sleep(20)\n"
        "print('sample', v.renderer.frames_rendered, v.renderer.gpu_memory()['allocated'], "
        "open(f'/proc/{os.getpid()}/status').read().split('VmRSS:')[1].split()[0], "
        "dvr._native.validation_messages())",
        "v.close()",
    ])
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    nb = Notebook(page, lab, name)
    started = time.perf_counter()
    nb.run(0)

    def sample():
        out = nb.run(1, timeout=120)
        frames, gpu, rss, messages = re.search(r"sample (\d+) (\d+) (\d+) (\d+)", out).groups()
        return int(frames), int(gpu) / 2**20, int(rss) / 1024, int(messages)

    samples = [sample()]
    while time.perf_counter() - started < seconds:
        time.sleep(max(0.0, min(60.0, seconds - (time.perf_counter() - started) - 20)))
        samples.append(sample())
    nb.run(2)
    page.close()
    warm, end = samples[0], samples[-1]
    return _row("notebook viewer", end[0], time.perf_counter() - started, (warm[2], end[2]),
                (warm[1], end[1]), end[3])

"""The wheel stands alone: installed into a fresh virtual environment, away from the
checkout, it finds its presets, the bundled MRI and the networks inside itself.

The wheel is ``$DVR_WHEEL``, else the one tools/test.sh builds (``target/wheels``)."""

import json
import os
import pathlib
import subprocess
import sys
import zipfile

import pytest

from conftest import ROOT

# Its presets, the MRI with its licence, the RAE networks and ours' young-pixel network
# (weights + manifests).
PACKAGED = [
    "dvr/assets/transfer/phantom-opaque.toml",
    "dvr/assets/transfer/ct-bone.toml",
    "dvr/assets/volumes/mni152_t1.nii.gz",
    "dvr/assets/volumes/LICENSE-MNI.txt",
    "dvr/assets/rae/mri.json",
    "dvr/assets/rae/mri.bin",
    "dvr/assets/rae/phantom.bin",
    "dvr/assets/young/young.json",
    "dvr/assets/young/young.bin",
]

SCRIPT = r"""
import json, os, sys, numpy as np, dvr
out = {"assets": str(dvr.assets_dir()), "package": os.path.dirname(dvr.__file__)}
r = dvr.Renderer(dvr.Scene.builtin("mri/point-light"), size=(32, 32), spp=2, denoisers=["ours"])
img = r.render(frame=0)
out["mri"] = [float(img["noisy"].mean()), float(img["ours"].mean())]
z, y, x = np.mgrid[:24, :24, :24] / 23.0 - 0.5
ball = (np.sqrt(x * x + y * y + z * z) < 0.35).astype(np.float32)
with dvr.Renderer(dvr.Scene(ball, tf="phantom-opaque"), size=(32, 32), spp=2, denoisers=[]) as p:
    out["preset"] = float(p.render()["noisy"].mean())
out["presets"] = sorted(dvr.TransferFunction.presets())
print(json.dumps(out))
"""


def _wheel():
    given = os.environ.get("DVR_WHEEL")
    found = [pathlib.Path(given)] if given else sorted((ROOT / "target/wheels").glob("dvr-*.whl"))
    if not found or not found[-1].is_file():
        pytest.fail("no wheel: set DVR_WHEEL or build one into target/wheels (tools/test.sh does)")
    return found[-1]


def test_the_wheel_carries_its_assets_and_stays_small():
    wheel = _wheel()
    names = zipfile.ZipFile(wheel).namelist()
    missing = [p for p in PACKAGED if p not in names]
    assert not missing, f"{wheel.name} lacks {missing}"
    # Only the folders the engine reads, not assets/ whole (results, gallery, scenes).
    read = ("transfer", "volumes", "rae", "young")
    assert not [n for n in names if n.startswith("dvr/assets/") and n.split("/")[2] not in read]
    assert wheel.stat().st_size < 60 << 20
    # python/dvr/assets links file by file: a new preset or network needs its link, and a
    # volume stored as a folder (OME-Zarr) a link per file inside it.
    shipped = {f"dvr/assets/{p.relative_to(ROOT / 'assets')}" for d in read
               for p in (ROOT / "assets" / d).rglob("*") if p.is_file() and p.name != "README.md"}
    assert not shipped - set(names), f"not linked under python/dvr/assets: {sorted(shipped - set(names))}"


def test_an_installed_wheel_renders_with_the_checkout_out_of_reach(tmp_path):
    wheel = _wheel()
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    py = venv / "bin/python"
    # The outer pip installs into the fresh environment: numpy from its cache, dvr from
    # the wheel alone.
    pip = [sys.executable, "-m", "pip", "--python", str(py), "install", "--quiet", "--disable-pip-version-check"]
    subprocess.run(pip + ["numpy"], check=True, timeout=120)
    subprocess.run(pip + ["--no-deps", str(wheel)], check=True, timeout=120)
    env = {k: v for k, v in os.environ.items() if k not in ("DVR_ASSETS", "PYTHONPATH", "VIRTUAL_ENV")}
    run = subprocess.run(
        [str(py), "-I", "-c", SCRIPT], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-3000:]
    out = json.loads(run.stdout.strip().splitlines()[-1])
    site = venv.resolve()
    # The assets it used are the wheel's own, inside the environment, not the checkout's.
    assets = pathlib.Path(out["assets"]).resolve()
    assert assets == pathlib.Path(out["package"]).resolve() / "assets"
    assert site in assets.parents and ROOT.resolve() not in assets.parents
    assert not (assets / "transfer").is_symlink()
    assert {"phantom-opaque", "ct-bone", "mri-opaque"} <= set(out["presets"])
    assert all(m > 0 for m in out["mri"]) and out["preset"] > 0

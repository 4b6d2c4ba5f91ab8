#!/usr/bin/env python3
"""The datasets that multi-channel and time-series rendering are tested and shown on,
written the way people's files are written (nibabel, tifffile, ome-zarr-py).

    tools/datasets.py {statmap,microscopy,beating-shell,mni-labels,all} [--out DIR]

`statmap` copies nilearn's sample statistical map (MNI space, 3 mm) out of the installed
nilearn wheel, byte for byte. `microscopy` is a synthetic 3-channel fluorescence stack
(nuclei, membranes, a sparse marker) with photon noise, as OME-Zarr and OME-TIFF.
`beating-shell` is a 4D NIfTI of a heart-like shell beating once over 24 time points,
with vessels on its wall that move with it. `mni-labels` segments the MNI152 template
into white matter, grey matter and the rest of the brain from its own tissue probability
maps (in nilearn's wheel), as a NIfTI label map with an ITK-SNAP label file.

Everything is made from fixed seeds and closed-form shapes, so a run writes the same
voxels as the files committed under `assets/volumes/` (the tests regenerate and compare).
"""

import argparse
import importlib.util
import pathlib
import shutil
import uuid

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
SEED = 20240607

# The sample map's place inside the nilearn package (nilearn's
# `datasets.load_sample_motor_activation_image`).
STATMAP = ("datasets", "data", "image_10426.nii.gz")

# Microscopy: (C, Z, Y, X) voxels of 1 µm along z and 0.5 µm across (a light-sheet
# stack: coarser along the detection axis).
SHAPE = (3, 64, 96, 96)
SPACING_UM = (1.0, 0.5, 0.5)
CHANNELS = [  # name, omero hex colour, OME RGBA
    ("nuclei", "0000FF", 0x0000FFFF),
    ("membranes", "00FF00", 0x00FF00FF),
    ("marker", "FF00FF", 0xFF00FFFF),
]
CAMERA_OFFSET = 100  # counts a dark pixel reads (sCMOS cameras add an offset)

# Beating shell: 96³ voxels of 1 mm, 24 time points over one beat.
GRID, TIMES = 96, 24
SEMI_AXES_MM = np.array([22.0, 19.0, 30.0])  # x, y, z of the outer wall at mean size
WALL_MM = 6.0
BEAT = 0.15  # the radius swings ±15 % about its mean
# Vessels on the outer wall as (polar, azimuth) paths in degrees: two trunks from the
# top and a branch off each (the branch starts on its trunk's path), tube radius in mm.
VESSELS = [
    ([(20, 0), (70, 15), (120, 25), (160, 30)], 2.0),
    ([(20, 0), (55, -60), (90, -120), (125, -170)], 1.8),
    ([(70, 15), (100, 55), (135, 80)], 1.3),
    ([(120, 25), (150, -10)], 1.2),
    ([(90, -120), (130, -95), (155, -70)], 1.3),
]


def statmap_source() -> pathlib.Path:
    """The map inside the installed nilearn (found without importing nilearn)."""
    spec = importlib.util.find_spec("nilearn")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("nilearn is not installed: pip install 'nilearn>=0.10'")
    return pathlib.Path(list(spec.submodule_search_locations)[0]).joinpath(*STATMAP)


def write_statmap(out: pathlib.Path) -> list:
    dst = out / "mni152_statmap.nii.gz"
    shutil.copyfile(statmap_source(), dst)
    return [dst]


def blur(a: np.ndarray, sigmas) -> np.ndarray:
    """Separable Gaussian blur, sigma in voxels per axis, edges extended."""
    for axis, s in enumerate(sigmas):
        if s <= 0:
            continue
        r = int(np.ceil(3 * s))
        k = np.exp(-0.5 * (np.arange(-r, r + 1) / s) ** 2)
        k /= k.sum()
        moved = np.moveaxis(a, axis, 0)
        p = np.concatenate([moved[:1].repeat(r, 0), moved, moved[-1:].repeat(r, 0)])
        acc = sum(w * p[i : i + moved.shape[0]] for i, w in enumerate(k))
        a = np.moveaxis(acc, 0, axis)
    return a


def microscopy_volume(seed: int = SEED) -> np.ndarray:
    """(C, Z, Y, X) uint16 counts: each channel's expected photons, blurred by the
    microscope's PSF, then Poisson noise over a dim background and a camera offset."""
    rng = np.random.default_rng(seed)
    _, nz, ny, nx = SHAPE
    extent = np.array([nz, ny, nx]) * SPACING_UM
    pos = np.stack(np.meshgrid(*[(np.arange(n) + 0.5) * s for n, s in zip((nz, ny, nx), SPACING_UM)], indexing="ij"), -1)

    # 40 cell centres at least 8 µm apart: nuclei never touch, and Voronoi cells are
    # the size of tissue culture cells.
    centres = []
    while len(centres) < 40:
        c = rng.uniform(3.0, extent - 3.0)
        if all(np.linalg.norm(c - o) >= 8.0 for o in centres):
            centres.append(c)

    # Nuclei: rotated ellipsoids of 2.5-3.8 µm semi-axes (under half the 8 µm spacing,
    # so each stays inside its cell) with a chromatin-like texture and their own brightness.
    nuclei = np.zeros(SHAPE[1:])
    for c in centres:
        rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        local = (pos - c) @ rot / rng.uniform(2.5, 3.8, 3)
        nuclei += np.where((local**2).sum(-1) <= 1.0, rng.uniform(0.6, 1.0), 0.0)
    texture = blur(rng.random(SHAPE[1:]), (1.0, 2.0, 2.0))
    nuclei *= np.clip(1.0 + 0.3 * (texture - texture.mean()) / texture.std(), 0.2, None)

    # Membranes: the Voronoi boundaries between cells (half the gap between the nearest
    # and second-nearest centre's distance is about the distance to their bisecting
    # plane), closed by a sphere of 7 µm where a cell has no neighbour.
    d1 = np.full(SHAPE[1:], np.inf)
    d2 = np.full(SHAPE[1:], np.inf)
    for c in centres:
        d = np.linalg.norm(pos - c, axis=-1)
        d2 = np.minimum(d2, np.maximum(d1, d))
        d1 = np.minimum(d1, d)
    bisector = np.where(d1 < 7.0, np.exp(-0.5 * ((d2 - d1) / 2 / 0.3) ** 2), 0.0)
    membranes = np.maximum(bisector, np.exp(-0.5 * ((d1 - 7.0) / 0.3) ** 2))

    # Marker: 6 spots about the PSF's size beside nuclei, over ten times brighter than
    # the nuclei.
    marker = np.zeros(SHAPE[1:])
    for i in rng.choice(len(centres), 6, replace=False):
        spot = centres[i] + rng.normal(size=3) / np.sqrt(3) * 4.0
        marker += np.exp(-0.5 * (np.linalg.norm(pos - spot, axis=-1) / 0.35) ** 2)

    # The PSF (σ 0.25 µm across, 0.8 µm along z), light lost with depth, and the photons
    # each channel peaks at.
    psf = [0.8 / SPACING_UM[0], 0.25 / SPACING_UM[1], 0.25 / SPACING_UM[2]]
    depth = np.exp(-pos[..., 0] / 150.0)
    photons = [600.0 * nuclei, 300.0 * membranes, 50000.0 * marker]
    out = np.empty(SHAPE, np.uint16)
    for ch, signal in enumerate(photons):
        expected = blur(signal, psf) * depth + 3.0
        counts = rng.poisson(expected) + CAMERA_OFFSET
        out[ch] = np.clip(counts, 0, 65535).astype(np.uint16)
    return out


def windows(data: np.ndarray) -> list:
    """Display windows per channel: the camera offset to the 99.9th percentile (the
    marker's to its brightest voxel: its spots are too few for a percentile)."""
    ends = [int(np.percentile(data[0], 99.9)), int(np.percentile(data[1], 99.9)), int(data[2].max())]
    return [(CAMERA_OFFSET, e) for e in ends]


def write_microscopy(out: pathlib.Path) -> list:
    import tifffile
    import zarr
    from ome_zarr.format import FormatV05
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image
    from zarr.codecs import BloscCodec

    data = microscopy_volume()
    z_um, y_um, x_um = SPACING_UM
    win = windows(data)

    zpath = out / "microscopy.ome.zarr"
    if zpath.exists():
        shutil.rmtree(zpath)
    fmt = FormatV05()
    root = zarr.group(store=parse_url(str(zpath), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
    omero = {"channels": [
        {"label": name, "color": hex_, "active": True,
         "window": {"start": s, "end": e, "min": 0, "max": 65535}}
        for (name, hex_, _), (s, e) in zip(CHANNELS, win)
    ]}  # fmt: skip
    # One chunk per channel, blosc-zstd over bit planes: photon noise compresses best
    # with its low bits apart from its high ones.
    write_image(
        image=data, group=root, fmt=fmt, axes="czyx", scale_factors=[],
        scale={"c": 1.0, "z": z_um, "y": y_um, "x": x_um},
        axes_units={"z": "micrometer", "y": "micrometer", "x": "micrometer"},
        storage_options={"chunks": (1, *SHAPE[1:]),
                         "compressors": [BloscCodec(cname="zstd", clevel=9, shuffle="bitshuffle")]},
        name="microscopy", omero=omero,
    )  # fmt: skip

    tpath = out / "microscopy.ome.tif"
    # OME's Color is a signed 32-bit RGBA.
    colours = [rgba - (1 << 32) if rgba >= 1 << 31 else rgba for _, _, rgba in CHANNELS]
    tifffile.imwrite(
        tpath, data, ome=True, compression="zlib", compressionargs={"level": 9},
        metadata={
            # A UUID of its own name rather than tifffile's time-based one, so that a
            # run writes the same bytes.
            "UUID": str(uuid.uuid5(uuid.NAMESPACE_URL, "dvr/assets/volumes/microscopy.ome.tif")),
            "Name": "microscopy",
            "axes": "CZYX",
            "Channel": {"Name": [n for n, _, _ in CHANNELS], "Color": colours},
            "PhysicalSizeX": x_um, "PhysicalSizeXUnit": "µm",
            "PhysicalSizeY": y_um, "PhysicalSizeYUnit": "µm",
            "PhysicalSizeZ": z_um, "PhysicalSizeZUnit": "µm",
        },
    )  # fmt: skip
    return [zpath, tpath]


def surface_point(polar_deg, azimuth_deg, scale: float, lift_mm: float) -> np.ndarray:
    """The point on the outer wall (at `scale` × its mean size) in the direction given by
    the angles, lifted `lift_mm` off the wall along its normal."""
    t, p = np.radians(polar_deg), np.radians(azimuth_deg)
    u = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    axes = SEMI_AXES_MM * scale
    on_wall = u / np.sqrt(((u / axes) ** 2).sum(-1, keepdims=True))
    normal = on_wall / axes**2
    return on_wall + lift_mm * normal / np.linalg.norm(normal, axis=-1, keepdims=True)


def beating_shell_frame(t: int) -> np.ndarray:
    """(X, Y, Z) density in [0, 1] at time point t: a wall of density 0.6 and vessels of
    0.9, edges anti-aliased over one voxel."""
    scale = 1.0 + BEAT * np.sin(2 * np.pi * t / TIMES)
    c = (np.arange(GRID) + 0.5) - GRID / 2  # voxel centres in mm, the grid's centre at 0
    x, y, z = np.meshgrid(c, c, c, indexing="ij")

    # Signed distance to an ellipsoid, approximated as (ρ - 1) × its mean semi-axis: a
    # voxel is inside the wall between the outer surface and the one WALL_MM within it.
    def signed(axes):
        rho = np.sqrt((x / axes[0]) ** 2 + (y / axes[1]) ** 2 + (z / axes[2]) ** 2)
        return (rho - 1.0) * axes.mean()

    outer = SEMI_AXES_MM * scale
    wall = np.clip(0.5 - signed(outer), 0, 1) * np.clip(0.5 + signed(outer - WALL_MM), 0, 1)
    density = 0.6 * wall

    # Vessels: each path densely sampled in angle, points carried by the wall's scale,
    # each sample a ball of the tube's radius stamped into a small box around it.
    for path, radius in VESSELS:
        angles = np.array(path, float)
        s = np.linspace(0, len(angles) - 1, 40 * (len(angles) - 1) + 1)
        polar = np.interp(s, np.arange(len(angles)), angles[:, 0])
        azimuth = np.interp(s, np.arange(len(angles)), angles[:, 1])
        for p in surface_point(polar, azimuth, scale, radius):
            i = p + GRID / 2 - 0.5  # voxel index of the point
            lo = np.maximum(np.floor(i - radius - 1).astype(int), 0)
            hi = np.minimum(np.ceil(i + radius + 2).astype(int), GRID)
            box = tuple(slice(a, b) for a, b in zip(lo, hi))
            d = np.sqrt((x[box] - p[0]) ** 2 + (y[box] - p[1]) ** 2 + (z[box] - p[2]) ** 2)
            density[box] = np.maximum(density[box], 0.9 * np.clip(radius + 0.5 - d, 0, 1))
    return density


# The MNI152 segmentation: (value, name, ITK-SNAP RGB, visible) of each label, made from
# the template's own tissue probability maps in nilearn's wheel. The rest of the brain
# (CSF, ventricles, partial volumes: the masked T1's other voxels) is a label of its own,
# hidden by default, so a view can hide every tissue and a view of the white and grey
# matter is what it was.
TISSUES = [
    (1, "White matter", (245, 240, 225), 1),
    (2, "Grey matter", (205, 110, 95), 1),
    (3, "Rest of the brain", (120, 160, 210), 0),
]


def write_mni_labels(out: pathlib.Path) -> list:
    """White matter where its probability passes one half, grey matter where its does
    (and white matter's does not), the rest of the brain where the brain-masked T1 is
    not zero; on the T1's grid, with an ITK-SNAP label file."""
    import nibabel as nib

    base = statmap_source().parent
    prob = {n: nib.load(base / f"mni_icbm152_{n}_tal_nlin_sym_09a_converted.nii.gz") for n in ("wm", "gm", "t1")}
    wm = prob["wm"].get_fdata() > 127.5
    gm = (prob["gm"].get_fdata() > 127.5) & ~wm
    rest = (prob["t1"].get_fdata() > 0) & ~wm & ~gm
    labels = np.select([wm, gm, rest], [1, 2, 3], 0).astype(np.uint8)
    img = nib.Nifti1Image(labels, prob["wm"].affine)
    img.header.set_xyzt_units("mm")
    img.header.set_qform(prob["wm"].affine, code=1)
    img.header.set_sform(prob["wm"].affine, code=1)
    path = out / "mni152_labels.nii.gz"
    nib.save(img, path)
    table = out / "mni152_labels.label"
    lines = [
        "################################################",
        "# ITK-SnAP Label Description File",
        "# Columns = IDX -R- -G- -B- -A-- VIS MSH LABEL",
        "################################################",
        '    0     0    0    0        0  0  0    "Clear Label"',
    ]
    lines += [f'{v:5d} {r:5d}{g:5d}{b:5d}        1  {vis}  1    "{name}"' for v, name, (r, g, b), vis in TISSUES]
    table.write_text("\n".join(lines) + "\n")
    return [path, table]


def write_beating_shell(out: pathlib.Path) -> list:
    import nibabel as nib

    data = np.stack([np.round(beating_shell_frame(t) * 255).astype(np.uint8) for t in range(TIMES)], -1)
    # RAS, 1 mm, the grid's centre at the origin; one beat a second.
    affine = np.eye(4)
    affine[:3, 3] = -GRID / 2 + 0.5
    img = nib.Nifti1Image(data, affine)
    img.header.set_xyzt_units("mm", "sec")
    img.header.set_zooms((1.0, 1.0, 1.0, 1.0 / TIMES))
    img.header.set_qform(affine, code=1)
    img.header.set_sform(affine, code=1)
    path = out / "beating_shell.nii.gz"
    nib.save(img, path)
    return [path]


WRITERS = {
    "statmap": write_statmap,
    "microscopy": write_microscopy,
    "beating-shell": write_beating_shell,
    "mni-labels": write_mni_labels,
}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", choices=[*WRITERS, "all"])
    ap.add_argument("--out", type=pathlib.Path, default=ROOT / "assets/volumes", help="folder (default: assets/volumes/)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name in WRITERS if args.dataset == "all" else [args.dataset]:
        for path in WRITERS[name](args.out):
            size = sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) if path.is_dir() else path.stat().st_size
            print(f"{path}  {size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()

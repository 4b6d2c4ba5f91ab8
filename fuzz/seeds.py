"""Writes the seed corpus of every fuzz target into fuzz/corpus/<target>/ (small valid
files of each format and variant the loaders read, plus the repository's scenes and
transfer functions). Run from anywhere: python3 fuzz/seeds.py. The OME-Zarr and
OME-TIFF seeds are written by zarr-python, ome-zarr and tifffile (pip install zarr
ome-zarr tifffile numpy); without them those two targets' seeds are left as they are.
Files that fuzzing found are added to the same folders by hand (see README
"Reliability")."""
import glob
import gzip
import os
import shutil
import struct
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CORPUS = os.path.join(HERE, "corpus")


def put(target, name, data):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def nifti(dims, code, bitpix, payload, pixdim=(1.0, 1.0, 1.0), scale=(0.0, 0.0), ndim=3):
    h = bytearray(352)
    struct.pack_into("<i", h, 0, 348)
    dim = [ndim, *dims, 1, 1, 1, 1][:8]
    struct.pack_into("<8h", h, 40, *dim)
    struct.pack_into("<hh", h, 70, code, bitpix)
    struct.pack_into("<8f", h, 76, 1.0, *pixdim, 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<fff", h, 108, 352.0, *scale)
    h[123] = 2
    h[344:348] = b"n+1\0"
    return bytes(h) + payload


def nifti_seeds():
    u8 = bytes(range(0, 240, 4))
    put("volume_nifti", "u8.nii", nifti((5, 4, 3), 2, 8, u8, (0.8, 0.9, 1.5)))
    put("volume_nifti", "u8.nii.gz", gzip.compress(nifti((5, 4, 3), 2, 8, u8), mtime=0))
    i16 = struct.pack("<12h", *range(-600, 600, 100))
    put("volume_nifti", "i16-scaled.nii", nifti((3, 2, 2), 4, 16, i16, scale=(2.0, -1000.0)))
    f32 = struct.pack("<8f", 0.0, 0.25, 0.5, 1.0, 2.0, -1.0, 0.125, 3.0)
    put("volume_nifti", "f32.nii", nifti((2, 2, 2), 16, 32, f32))
    u16 = struct.pack("<4H", 0, 1000, 65535, 7)
    put("volume_nifti", "u16-2d.nii", nifti((2, 2, 1), 512, 16, u16, ndim=2))


def nrrd_header(t, sizes, enc, extra=""):
    return (f"NRRD0004\n# seed\ntype: {t}\ndimension: {len(sizes)}\nsizes: {' '.join(map(str, sizes))}\n"
            f"encoding: {enc}\nendian: little\n{extra}")


def nrrd_seeds():
    data = bytes(range(24))
    put("volume_nrrd", "raw.nrrd", (nrrd_header("uint8", (2, 3, 4), "raw", "spacings: 1 2 3\n\n")).encode() + data)
    put("volume_nrrd", "gzip.nrrd", (nrrd_header("uint8", (2, 3, 4), "gzip",
                                                  "space directions: (1,0,0) (0,2,0) (0,0,3)\n\n")).encode()
        + gzip.compress(data, mtime=0))
    i16 = struct.pack("<8h", -1000, -500, 0, 500, 1000, 1500, 2000, 2500)
    put("volume_nrrd", "i16-4d.nrrd", (nrrd_header("short", (1, 2, 2, 2), "raw",
                                                    "spacings: nan 0.5 0.5 3\nmodality:=CT\n\n")).encode() + i16)
    f32 = struct.pack(">4f", 0.0, 0.5, 1.0, 0.25)
    put("volume_nrrd", "f32-big.nrrd",
        nrrd_header("float", (2, 2), "raw", "\n").replace("endian: little", "endian: big").encode() + f32)
    put("volume_nrrd", "skip.nrrd", (nrrd_header("uint8", (2, 2, 2), "raw", "byte skip: -1\n\n")).encode()
        + b"junk" + bytes(range(8)))


def nhdr_seeds():
    put("volume_nhdr", "raw.nhdr", nrrd_header("uint8", (4, 4, 16), "raw", "data file: data.raw\n"))
    put("volume_nhdr", "gzip.nhdr", nrrd_header("uint8", (4, 4, 16), "gzip",
                                                "space directions: (1,0,0) (0,1,0) (0,0,2)\ndata file: data.raw.gz\n"))
    put("volume_nhdr", "skips.nhdr", nrrd_header("uchar", (241, 1, 1), "raw",
                                                 "line skip: 1\nbyte skip: 4\ndata file: ./data.raw\n"))
    put("volume_nhdr", "tail.nhdr", nrrd_header("uchar", (8, 8, 2), "raw", "byte skip: -1\ndatafile: data.raw\n"))


def raw_seeds():
    put("volume_raw", "u8", bytes([1, 1, 1, 0]) + bytes(range(8)))
    put("volume_raw", "u16", bytes([1, 1, 0, 1]) + struct.pack("<4H", 0, 100, 60000, 7))
    put("volume_raw", "i16", bytes([1, 0, 0, 2]) + struct.pack("<2h", -1000, 1000))
    put("volume_raw", "f32-nan", bytes([1, 0, 0, 3]) + struct.pack("<2f", 0.5, float("nan")))


def dicom_element(tag, vr, value, explicit=True):
    if len(value) % 2:
        value += b"\0" if vr in (b"UI", b"OB", b"OW") else b" "
    out = struct.pack("<HH", *tag)
    if explicit:
        out += vr
        if vr in (b"OB", b"OW", b"SQ", b"UN", b"UT"):
            out += b"\0\0" + struct.pack("<I", len(value))
        else:
            out += struct.pack("<H", len(value))
    else:
        out += struct.pack("<I", len(value))
    return out + value


def dicom_slice(z, explicit=True, bits=16, signed=True):
    syntax = b"1.2.840.10008.1.2.1" if explicit else b"1.2.840.10008.1.2"
    meta = dicom_element((2, 1), b"OB", b"\0\1") + dicom_element((2, 0x10), b"UI", syntax)
    out = b"\0" * 128 + b"DICM" + dicom_element((2, 0), b"UL", struct.pack("<I", len(meta))) + meta
    e = lambda tag, vr, v: dicom_element(tag, vr, v, explicit)
    ds = lambda *v: "\\".join(str(x) for x in v).encode()
    out += e((0x18, 0x50), b"DS", ds(3.0))
    out += e((0x20, 0x0E), b"UI", b"1.2.3.4")
    out += e((0x20, 0x13), b"IS", ds(z + 1))
    out += e((0x20, 0x32), b"DS", ds(-10.0, -20.0, 5.0 + 2.5 * z))
    out += e((0x20, 0x37), b"DS", ds(1, 0, 0, 0, 1, 0))
    # An undefined-length sequence the reader skips.
    out += struct.pack("<HH", 0x0008, 0x1115) + (b"SQ\0\0" if explicit else b"") + struct.pack("<I", 0xFFFFFFFF)
    out += struct.pack("<HHI", 0xFFFE, 0xE000, 0xFFFFFFFF) + e((0x08, 0x1150), b"UI", b"1.2") \
        + struct.pack("<HHI", 0xFFFE, 0xE00D, 0) + struct.pack("<HHI", 0xFFFE, 0xE0DD, 0)
    out += e((0x28, 0x02), b"US", struct.pack("<H", 1))
    out += e((0x28, 0x10), b"US", struct.pack("<H", 3))
    out += e((0x28, 0x11), b"US", struct.pack("<H", 4))
    out += e((0x28, 0x30), b"DS", ds(0.7, 0.6))
    out += e((0x28, 0x100), b"US", struct.pack("<H", bits))
    out += e((0x28, 0x101), b"US", struct.pack("<H", 12 if bits == 16 else 8))
    out += e((0x28, 0x103), b"US", struct.pack("<H", int(signed)))
    out += e((0x28, 0x1052), b"DS", ds(-1024))
    out += e((0x28, 0x1053), b"DS", ds(1))
    pixels = struct.pack("<12h", *[z * 100 + i for i in range(12)]) if bits == 16 else bytes(range(12))
    out += e((0x7FE0, 0x10), b"OW" if bits == 16 else b"OB", pixels)
    return out


def dicom_seeds():
    sep = b"\n--next-slice--\n"
    put("volume_dicom", "one-slice", dicom_slice(0))
    put("volume_dicom", "three-slices", sep.join([dicom_slice(2), dicom_slice(0, explicit=False), dicom_slice(1)]))
    put("volume_dicom", "u8-two", sep.join([dicom_slice(0, bits=8, signed=False), dicom_slice(1, bits=8, signed=False)]))


def text_seeds():
    put("scene_toml", "example.toml", open(os.path.join(ROOT, "assets/scenes/example.toml")).read())
    put("scene_toml", "minimal.toml", '[volume]\nbuiltin = "cloud"\nsize = 8\n[transfer]\na = "cloud"\n'
                                      'b = "cloud-edit"\n[[light]]\nkind = "point"\nposition = [1.0, 1.0, 1.0]\n'
                                      'intensity = 10\n[animation]\nframes = 10\n[[animation.tf]]\nframe = 9\nblend = 1.0\n'
                                      '[[animation.light]]\nindex = 0\nframe = 5\nposition = [-1.0, 1.0, 1.0]\n'
                                      'interpolation = "step"\n')
    put("scene_toml", "orbit-area-env.toml", '[volume]\nbuiltin = "phantom"\nsize = 8\ndensity_scale = 150\n'
                                             '[transfer]\na = "phantom-opaque"\n[camera]\nposition = [0.5, 1.5, 0.3]\n'
                                             '[[light]]\nkind = "area"\nposition = [0.8, 0.9, 0.9]\ntarget = [0, 0, 0]\n'
                                             'size = [0.5, 0.3]\nintensity = 40\n[[light]]\nkind = "environment"\n'
                                             'mode = "gradient"\ntop = [0.5, 0.6, 0.8]\nbottom = [0.2, 0.2, 0.1]\n'
                                             'intensity = 0.25\n[render]\nestimator = "ray-march"\nphase = "hybrid"\n'
                                             'hg_g = 0.3\n[animation]\nframes = 30\n[animation.orbit]\n'
                                             'degrees_per_frame = 2\n[[animation.camera]]\nframe = 20\nfov_y_degrees = 30\n')
    for p in sorted(glob.glob(os.path.join(ROOT, "assets/transfer/*.toml"))):
        shutil.copy(p, os.path.join(CORPUS, "tf_toml", os.path.basename(p)))


ZARR_FILE_MARKER = b"\n--file "


def zarr_input(folder, open_path=".", budget=None):
    """A volume_zarr input (fuzz/src/entries.rs): the header line (the path to open
    and the memory budget), then each file under `folder` as a record."""
    out = f"{open_path} {budget if budget is not None else ''}".strip().encode()
    for root, dirs, files in os.walk(folder):
        dirs.sort()
        for f in sorted(files):
            path = os.path.join(root, f)
            data = open(path, "rb").read()
            assert ZARR_FILE_MARKER not in data, path  # would split the record
            out += ZARR_FILE_MARKER + os.path.relpath(path, folder).encode() + b"\n" + data
    assert len(out) <= 8192, (folder, len(out))  # small enough to fuzz fast
    return out


def ome_group(path, zarr_format, axes, levels, global_scale=None):
    """A group holding OME multiscales metadata (0.5 on Zarr v3, 0.4 on v2) for
    `levels` [(path, scale)], written by zarr-python."""
    import zarr

    image = {"axes": axes,
             "datasets": [{"path": p, "coordinateTransformations": [{"type": "scale", "scale": s}]}
                          for p, s in levels]}
    if global_scale:
        image["coordinateTransformations"] = [{"type": "scale", "scale": global_scale}]
    root = zarr.open_group(path, mode="w", zarr_format=zarr_format)
    if zarr_format == 3:
        root.attrs["ome"] = {"version": "0.5", "multiscales": [image]}
    else:
        root.attrs["multiscales"] = [dict(image, version="0.4")]
    return root


def zarr_seeds():
    import numcodecs
    import numpy as np
    import zarr
    from ome_zarr.format import FormatV04, FormatV05
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image
    from zarr.codecs import BloscCodec, BytesCodec, GzipCodec, TransposeCodec

    space = lambda n, unit="micrometer": {"name": n, "type": "space", "unit": unit}
    with tempfile.TemporaryDirectory() as tmp:
        def folder(name):
            return os.path.join(tmp, name)

        # ome-zarr's multiscale pyramids: OME-Zarr 0.5 (Zarr v3, zstd) and 0.4 (Zarr v2,
        # blosc), opened as the image (the finest level that fits) and as one level.
        z, y, x = np.meshgrid(np.arange(8), np.arange(12), np.arange(16), indexing="ij")
        u16 = (z * 97 + y * 13 + x * 3 + (x * y) % 7).astype(np.uint16)
        for name, fmt, data, extra in [
            ("ome05-pyramid", FormatV05(), u16, {}),
            ("ome04-pyramid-blosc", FormatV04(), (u16 % 251).astype(np.uint8),
             {"storage_options": {"compressor": numcodecs.Blosc(cname="lz4")}}),
        ]:
            root = zarr.group(store=parse_url(folder(name), mode="w", fmt=fmt).store, zarr_format=fmt.zarr_format)
            write_image(image=data, group=root, fmt=fmt, axes="zyx",
                        scale_factors=[{"z": 2, "y": 2, "x": 2}, {"z": 4, "y": 4, "x": 4}],
                        scale={"z": 2.0, "y": 0.5, "x": 0.25}, axes_units={a: "micrometer" for a in "zyx"}, **extra)
            put("volume_zarr", name, zarr_input(folder(name)))
        put("volume_zarr", "ome05-level-s1", zarr_input(folder("ome05-pyramid"), "s1"))

        # A level 0 over the 64 KiB budget, mostly empty (its empty chunks are not
        # written: they read as the fill value): the budget picks level s1.
        big = np.zeros((40, 40, 48), np.uint8)
        big[10:14, 8:20, 8:24] = 200
        fmt = FormatV05()
        root = zarr.group(store=parse_url(folder("budget"), mode="w", fmt=fmt).store, zarr_format=3)
        write_image(image=big, group=root, fmt=fmt, axes="zyx", scale_factors=[{"z": 2, "y": 2, "x": 2}],
                    storage_options={"chunks": (16, 16, 16)})
        put("volume_zarr", "ome05-budget-64k", zarr_input(folder("budget"), ".", 65536))

        # Zarr v3 by zarr-python: a float32 czyx image in gzip, two channels.
        root = ome_group(folder("czyx"), 3, [{"name": "c", "type": "channel"}] + [space(a) for a in "zyx"],
                         [("0", [1.0, 3.0, 1.0, 1.0])])
        a = root.create_array("0", shape=(2, 3, 4, 5), chunks=(1, 3, 2, 5), dtype="float32",
                              compressors=[GzipCodec(level=1)])
        a[:] = np.linspace(-1.0, 2.0, 120, dtype=np.float32).reshape(2, 3, 4, 5)
        put("volume_zarr", "v3-czyx-gzip-f32", zarr_input(folder("czyx")))

        # Zarr v3 sharding (gzip inner chunks, a crc32c index).
        root = ome_group(folder("sharded"), 3, [space(a, "millimeter") for a in "zyx"], [("0", [1.0, 1.0, 1.0])])
        a = root.create_array("0", shape=(4, 8, 8), chunks=(2, 4, 4), shards=(4, 8, 8), dtype="int16",
                              compressors=[GzipCodec(level=1)])
        a[:] = (np.arange(256, dtype=np.int16) * 37 - 4000).reshape(4, 8, 8)
        put("volume_zarr", "v3-sharded-i16", zarr_input(folder("sharded")))

        # Zarr v3 transpose codec and blosc (lz4, bit shuffle), opened as its level.
        root = ome_group(folder("transpose"), 3, [space(a, "nanometer") for a in "zyx"], [("0", [500.0, 400.0, 300.0])])
        a = root.create_array("0", shape=(3, 4, 5), chunks=(3, 4, 5), dtype="uint8",
                              filters=[TransposeCodec(order=[2, 1, 0])], serializer=BytesCodec(),
                              compressors=[BloscCodec(cname="lz4", shuffle="bitshuffle")])
        a[:] = np.arange(60, dtype=np.uint8).reshape(3, 4, 5) * 4
        put("volume_zarr", "v3-transpose-blosc-level0", zarr_input(folder("transpose"), "0"))

        # Zarr v2: 5D tczyx, big-endian uint16 in Fortran order, no compressor, "/" chunk
        # keys, one chunk left out (the fill value), a global scale.
        axes = [{"name": "t", "type": "time"}, {"name": "c", "type": "channel"}] + [space(a) for a in "zyx"]
        root = ome_group(folder("tczyx"), 2, axes, [("0", [1.0, 1.0, 2.0, 1.0, 1.0])], [1.0, 1.0, 1.0, 0.5, 0.5])
        a = root.create_array("0", shape=(1, 2, 2, 3, 4), chunks=(1, 1, 1, 3, 4), dtype=">u2", compressors=None,
                              order="F", fill_value=7, chunk_key_encoding={"name": "v2", "separator": "/"})
        a[:] = np.arange(48).reshape(1, 2, 2, 3, 4) * 1000
        shutil.rmtree(os.path.join(folder("tczyx"), "0", "0", "0", "1"))
        put("volume_zarr", "v2-tczyx-raw-missing", zarr_input(folder("tczyx")))

        # Zarr v2 blosc (zstd, byte shuffle) float32.
        root = ome_group(folder("v2blosc"), 2, [space(a) for a in "zyx"], [("0", [1.0, 1.0, 1.0])])
        a = root.create_array("0", shape=(3, 4, 5), chunks=(2, 4, 5), dtype="<f4",
                              compressors=numcodecs.Blosc(cname="zstd", shuffle=1))
        a[:] = np.arange(60, dtype=np.float32).reshape(3, 4, 5) - 20.0
        put("volume_zarr", "v2-blosc-f32", zarr_input(folder("v2blosc")))


def tiff_strips(pages, compression, encode, description):
    """A little-endian TIFF of uint8 `pages` (2D numpy arrays), one strip each, in a
    compression tifffile cannot write without imagecodecs (PackBits, LZW)."""
    entries = lambda n: 2 + 12 * n + 4
    out = bytearray(b"II*\0" + struct.pack("<I", 8))
    desc = description.encode() + b"\0"
    strips = [encode(p.tobytes()) for p in pages]
    n_tags = 10
    # Layout: IFDs back to back (the first has ImageDescription), then the description,
    # then the strips.
    sizes = [entries(n_tags + 1)] + [entries(n_tags)] * (len(pages) - 1)
    ifd_at = [8 + sum(sizes[:i]) for i in range(len(pages))]
    data_at = 8 + sum(sizes)
    desc_at = data_at
    strip_at = []
    at = desc_at + len(desc)
    for s in strips:
        strip_at.append(at)
        at += len(s)
    for i, p in enumerate(pages):
        h, w = p.shape
        tags = [(256, 3, 1, w), (257, 3, 1, h), (258, 3, 1, 8), (259, 3, 1, compression), (262, 3, 1, 1)]
        if i == 0:
            tags.append((270, 2, len(desc), desc_at))
        tags += [(273, 4, 1, strip_at[i]), (277, 3, 1, 1), (278, 3, 1, h), (279, 4, 1, len(strips[i])),
                 (339, 3, 1, 1)]
        ifd = struct.pack("<H", len(tags))
        for tag, typ, count, value in tags:
            ifd += struct.pack("<HHI", tag, typ, count) + (struct.pack("<HH", value, 0) if typ == 3 else struct.pack("<I", value))
        ifd += struct.pack("<I", ifd_at[i + 1] if i + 1 < len(pages) else 0)
        assert len(ifd) == sizes[i]
        out += ifd
    out += desc
    for s in strips:
        out += s
    return bytes(out)


def packbits(data):
    out, i = bytearray(), 0
    while i < len(data):
        j = i
        while j < len(data) and j - i < 128 and data[j] == data[i]:
            j += 1
        if j - i >= 3:
            out += bytes([257 - (j - i), data[i]])
            i = j
        else:
            k = i + 1
            while k < len(data) and k - i < 128 and not (k + 2 < len(data) and data[k] == data[k + 1] == data[k + 2]):
                k += 1
            out += bytes([k - i - 1]) + data[i:k]
            i = k
    return bytes(out)


def tiff_lzw(data):
    """TIFF's LZW (MSB first, codes widen one code early, Clear 256, EOI 257)."""
    table = {bytes([i]): i for i in range(256)}
    next_code, width, bits, nbits, out = 258, 9, 0, 0, bytearray()

    def emit(code):
        nonlocal bits, nbits
        bits, nbits = (bits << width) | code, nbits + width
        while nbits >= 8:
            nbits -= 8
            out.append((bits >> nbits) & 0xFF)

    emit(256)
    w = b""
    for c in data:
        wc = w + bytes([c])
        if wc in table:
            w = wc
            continue
        emit(table[w])
        table[wc] = next_code
        next_code += 1
        if next_code + 1 >= 1 << width and width < 12:
            width += 1
        w = bytes([c])
    if w:
        emit(table[w])
    emit(257)
    if nbits:
        out.append((bits << (8 - nbits)) & 0xFF)
    return bytes(out)


def tiff_seeds():
    import numpy as np
    import tifffile

    uuid = {"UUID": "urn:uuid:00000000-0000-0000-0000-000000000000"}  # the same bytes every run
    with tempfile.TemporaryDirectory() as tmp:
        def write(name, data, **kw):
            path = os.path.join(tmp, name)
            kw["metadata"] = dict(uuid, **kw.get("metadata", {"axes": "ZYX"})) if kw.get("ome", True) else None
            tifffile.imwrite(path, data, **kw)
            b = open(path, "rb").read()
            assert len(b) <= 8192, (name, len(b))
            put("volume_ome_tiff", name, b)

        z, y, x = np.meshgrid(np.arange(4), np.arange(12), np.arange(16), indexing="ij")
        ramp = z * 500 + y * 20 + x
        write("u16-none.ome.tif", ramp.astype(np.uint16), resolution=(4.0, 4.0), ome=True)
        write("u8-zlib.ome.tif", (ramp % 256).astype(np.uint8)[:, :8, :8].repeat(2, 0), compression="zlib", ome=True)
        write("i16-deflate-predictor-bigtiff.ome.tif", (ramp - 1000).astype(np.int16), compression="deflate",
              predictor=True, bigtiff=True, ome=True)
        write("f32-tiles-bigendian.ome.tif", (ramp / 100.0).astype(np.float32)[:2], tile=(16, 16),
              byteorder=">", ome=True)
        # Channels and time points around z (XYCZT: channels run fastest), physical sizes.
        czt = (np.arange(2 * 3 * 2 * 8 * 8) % 200).astype(np.uint8).reshape(2, 3, 2, 8, 8)
        write("tzc-sizes.ome.tif", czt, ome=True,
              metadata={"axes": "TZCYX", "PhysicalSizeX": 0.5, "PhysicalSizeY": 0.5, "PhysicalSizeZ": 0.002,
                        "PhysicalSizeZUnit": "mm"})
        write("u16-lzma.ome.tif", ramp.astype(np.uint16)[:2], compression="lzma", ome=True)
        # A sub-resolution pyramid (SubIFDs) under the full-resolution pages.
        path = os.path.join(tmp, "pyramid.ome.tif")
        with tifffile.TiffWriter(path, ome=True) as w:
            full = (ramp % 256).astype(np.uint8)
            w.write(full, subifds=1, metadata=dict(uuid, axes="ZYX"), compression="zlib")
            w.write(full[:, ::2, ::2], subfiletype=1, compression="zlib")
        put("volume_ome_tiff", "pyramid.ome.tif", open(path, "rb").read())
        # A plain (not OME) stack: pages as z slices of 1 mm voxels.
        write("plain-stack.tif", (ramp % 256).astype(np.uint8)[:3, :6, :6], ome=False, photometric="minisblack")
        # PackBits and LZW (which tifffile writes only with imagecodecs), by hand.
        ome = ('<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06">'
               '<Image ID="Image:0"><Pixels ID="Pixels:0" DimensionOrder="XYZCT" Type="uint8" SizeX="16" SizeY="12" '
               'SizeZ="3" SizeC="1" SizeT="1" PhysicalSizeX="1.5" PhysicalSizeY="1.5" PhysicalSizeZ="4.0">'
               '<Channel ID="Channel:0:0" SamplesPerPixel="1"/></Pixels></Image></OME>')
        blob = np.zeros((3, 12, 16), np.uint8)
        blob[:, 3:9, 4:12] = (np.arange(3) * 60 + 60)[:, None, None]
        blob[:, 5, :] = np.arange(16) * 9
        put("volume_ome_tiff", "u8-packbits.ome.tif", tiff_strips(list(blob), 32773, packbits, ome))
        put("volume_ome_tiff", "u8-lzw.ome.tif", tiff_strips(list(blob), 5, tiff_lzw, ome))


if __name__ == "__main__":
    os.makedirs(os.path.join(CORPUS, "tf_toml"), exist_ok=True)
    nifti_seeds()
    nrrd_seeds()
    nhdr_seeds()
    raw_seeds()
    dicom_seeds()
    text_seeds()
    try:
        import numpy, numcodecs, ome_zarr, tifffile, zarr  # noqa: F401
    except ImportError as e:
        print(f"{e}: volume_zarr and volume_ome_tiff seeds not written (pip install zarr ome-zarr tifffile numpy)")
    else:
        # gzip writes the time into each member's header: the epoch instead, so the seeds
        # are the same bytes every run.
        import types
        real_time, gzip.time = gzip.time, types.SimpleNamespace(time=lambda: 0)
        try:
            zarr_seeds()
        finally:
            gzip.time = real_time
        tiff_seeds()
    print("seeds in", CORPUS)

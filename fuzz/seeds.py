"""Writes the seed corpus of every fuzz target into fuzz/corpus/<target>/ (small valid
files of each format and variant the loaders read, plus the repository's scenes and
transfer functions). Run from anywhere: python3 fuzz/seeds.py. Files that fuzzing
found are added to the same folders by hand (see README "Reliability")."""
import glob
import gzip
import os
import shutil
import struct

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


if __name__ == "__main__":
    os.makedirs(os.path.join(CORPUS, "tf_toml"), exist_ok=True)
    nifti_seeds()
    nrrd_seeds()
    nhdr_seeds()
    raw_seeds()
    dicom_seeds()
    text_seeds()
    print("seeds in", CORPUS)

"""Captures of :class:`dvr.Viewer`: a screenshot (the shown frame as a lossless PNG at
the render size) and an orbit movie (MP4). Both use the eval's tone map
(``_native.encode_image``), so a capture matches the CLI's PNGs; the movie is encoded
by ``ffmpeg`` with the settings of the CLI's ``--video`` (``src/video.rs``: libx264,
CRF 18, yuv420p, even sizes, ``+faststart``, written under a temporary name and renamed
when ffmpeg succeeded, so a failed movie never leaves a file that looks whole)."""

import os
import pathlib
import shutil
import subprocess

import numpy as np

from . import _native

FFMPEG = "ffmpeg"


def write_png(image, path):
    """``image`` ((h, w, 3) linear radiance) as a PNG at ``path``; returns the path."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = _native.encode_image(np.ascontiguousarray(image, dtype=np.float32), "png")
    partial = path.with_name(path.name + ".partial")
    partial.write_bytes(data)
    os.replace(partial, path)
    return path


def ffmpeg_missing():
    """Why a movie cannot be written here, or None."""
    if shutil.which(FFMPEG) is None:
        return f"a movie needs `{FFMPEG}` on PATH (Debian/Ubuntu: apt install ffmpeg)"
    return None


class Movie:
    """An MP4 being written: :meth:`add` frames (linear radiance, all one size), then
    :meth:`finish`. The frames go to ffmpeg as PNGs (tone-mapped as the eval's)."""

    def __init__(self, path, fps=30):
        why = ffmpeg_missing()
        if why:
            raise RuntimeError(why)
        if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= 240:
            raise ValueError(f"fps={fps!r}: must be a whole number from 1 to 240")
        self.path = pathlib.Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.partial = self.path.with_name(self.path.stem + ".partial.mp4")
        self.size = None
        self.frames = 0
        self._proc = subprocess.Popen(
            [FFMPEG, "-hide_banner", "-loglevel", "error", "-y",
             "-f", "image2pipe", "-c:v", "png", "-framerate", str(fps), "-i", "-",
             # yuv420p needs even sizes: odd ones get one black column or row.
             "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
             "-c:v", "libx264", "-preset", "medium", "-crf", "18",
             "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4", str(self.partial)],
            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        )

    def add(self, image):
        if self.size is None:
            self.size = image.shape[:2]
        elif image.shape[:2] != self.size:
            self.abort()
            raise ValueError(f"{self.path}: a frame is {image.shape[1]}x{image.shape[0]}, the others {self.size[1]}x{self.size[0]}")
        try:
            self._proc.stdin.write(_native.encode_image(np.ascontiguousarray(image, dtype=np.float32), "png"))
        except BrokenPipeError:
            _, err = self._proc.communicate()
            self._cleanup()
            raise RuntimeError(f"{FFMPEG} stopped ({self._proc.returncode}) while writing {self.path}: {err.decode(errors='replace').strip()}") from None
        self.frames += 1

    def finish(self):
        """Waits for ffmpeg; the movie is at its path after this, or an error says why."""
        if self.frames == 0:
            self.abort()
            raise RuntimeError(f"{self.path}: no frames were added")
        _, err = self._proc.communicate()
        if self._proc.returncode != 0:
            self._cleanup()
            raise RuntimeError(f"{FFMPEG} failed ({self._proc.returncode}) writing {self.path}: {err.decode(errors='replace').strip()}")
        os.replace(self.partial, self.path)
        return self.path

    def abort(self):
        if self._proc.poll() is None:
            self._proc.kill()
            self._proc.communicate()
        self._cleanup()

    def _cleanup(self):
        try:
            self.partial.unlink()
        except FileNotFoundError:
            pass


def orbit_cameras(camera, frames, degrees):
    """``frames`` cameras orbiting ``degrees`` about the camera's up axis through its
    target (the first is the camera itself), keeping distance and height."""
    pos, target = np.asarray(camera["position"], float), np.asarray(camera["target"], float)
    up = np.asarray(camera["up"], float)
    up /= np.linalg.norm(up)
    offset = pos - target
    cams = []
    for i in range(frames):
        a = np.radians(degrees * i / frames)
        # Rodrigues' rotation of the offset about `up`.
        rotated = offset * np.cos(a) + np.cross(up, offset) * np.sin(a) + up * np.dot(up, offset) * (1 - np.cos(a))
        cams.append(dict(camera, position=(target + rotated).tolist()))
    return cams

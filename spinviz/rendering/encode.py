"""Video and image writers.  They write where they are told: callers hand them the
temporary file of a ``spinviz.atomic.AtomicPath`` (renamed into place only on success), so
nothing half-written ever sits at the output path."""

from __future__ import annotations

import logging
import os

import numpy as np
from PIL import Image

# imageio-ffmpeg warns when a writer closes before its first frame: a worker told to stop
# early does exactly that, and its segment is discarded anyway.
logging.getLogger("imageio_ffmpeg").setLevel(logging.ERROR)


class Mp4Writer:
    """H.264 (libx264), yuv420p, through imageio-ffmpeg's ffmpeg (a separate process, so
    encoding runs beside rendering).  Width and height must be even."""

    def __init__(self, path: str, size, fps: int, crf: int = 20, preset: str = "veryfast", threads: int = 0):
        import imageio_ffmpeg

        W, H = size                            # even: checked by RenderSpec.check_output
        params = ["-preset", preset, "-crf", str(crf), "-movflags", "+faststart", "-f", "mp4"]
        if threads:
            params += ["-threads", str(threads)]
        self._gen = imageio_ffmpeg.write_frames(
            path, (W, H), fps=fps, codec="libx264", pix_fmt_in="rgb24", pix_fmt_out="yuv420p", quality=None,
            macro_block_size=2, ffmpeg_log_level="error", output_params=params,
        )
        self._gen.send(None)

    def write(self, img: np.ndarray):
        """Encode one frame: RGB, shape (H, W, 3), uint8."""
        self._gen.send(np.ascontiguousarray(img))

    def close(self):
        """Finish the file (ffmpeg exits)."""
        self._gen.close()

    abort = close                          # stop ffmpeg; the caller discards the temporary file


class GifWriter:
    """Animated GIF via Pillow, frames kept in memory.

    One palette for the whole animation, from the first, middle and last frames side by side
    (so colours that appear late, like a filled time bar, are in it): what does not move keeps
    its palette index from frame to frame, and Pillow stores only each frame's changed box --
    the text bands cost nothing after the first frame.  Frames are kept as RGB until then."""

    def __init__(self, path: str, size, fps: int, colors: int = 128):
        self.path, self.fps, self.frames, self.colors = path, fps, [], colors

    def write(self, img: np.ndarray):
        """Keep one frame: RGB, shape (H, W, 3), uint8."""
        self.frames.append(Image.fromarray(np.ascontiguousarray(img)))

    def abort(self):
        """Drop the frames: nothing is quantized or written (the caller discards the file)."""
        self.frames = []

    def close(self):
        """Quantize all frames to one palette and write the GIF."""
        if self.frames:
            picks = [self.frames[0], self.frames[len(self.frames) // 2], self.frames[-1]]
            w, h = picks[0].size
            mosaic = Image.new("RGB", (w * len(picks), h))
            for i, im in enumerate(picks):
                mosaic.paste(im, (i * w, 0))
            palette = mosaic.quantize(colors=self.colors, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
            self.frames = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in self.frames]
            self.frames[0].save(self.path, format="GIF", save_all=True, append_images=self.frames[1:],
                                duration=int(round(1000 / self.fps)), loop=0, optimize=True, disposal=1)


def open_writer(path: str, size, fps: int):
    """An ``Mp4Writer`` or ``GifWriter`` by the extension of ``path``; size (width, height) px."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".mp4":
        return Mp4Writer(path, size, fps)
    if ext == ".gif":
        return GifWriter(path, size, fps)
    raise ValueError(f"unknown video format {ext!r}; use .mp4 or .gif")


def save_png(path: str, img: np.ndarray):
    """An RGB frame as PNG (callers write to an ``AtomicPath``'s temporary file)."""
    Image.fromarray(img).save(path, format="PNG")

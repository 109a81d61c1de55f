"""Headless Chromium for the tests of web pages (the docs site, the atlas page): Debian's
``chromium`` package, no network, no display."""

from __future__ import annotations

import html
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

# Flags for a root user on a machine whose network is closed: without the background
# networking ones Chromium keeps trying (and failing) to reach Google's hosts.
# WebGL on Chromium's software renderer (SwiftShader): without this flag its automatic use is
# deprecated and may end; a page that draws with WebGL (the glTF page) asks for it.
WEBGL_FLAGS = ("--enable-unsafe-swiftshader",)
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--hide-scrollbars", "--virtual-time-budget=10000"]


def chromium(page: Path, tmp_path: Path, *args: str, fragment: str = "") -> subprocess.CompletedProcess:
    """Run Chromium on ``page`` (a file; ``fragment``: what follows '#' in its address)."""
    profile = tmp_path / f"profile-{page.stem}-{len(list(tmp_path.iterdir()))}"
    uri = page.as_uri() + (f"#{fragment}" if fragment else "")
    r = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args, uri],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r


def screenshot(page: Path, tmp_path: Path, size=(1280, 900), fragment: str = "", flags=()) -> np.ndarray:
    """The page as Chromium draws it, RGB (height, width, 3); ``flags``: more Chromium flags."""
    from PIL import Image

    png = tmp_path / f"{page.stem}-{len(list(tmp_path.iterdir()))}.png"
    chromium(page, tmp_path, *flags, f"--screenshot={png}", f"--window-size={size[0]},{size[1]}", fragment=fragment)
    return np.asarray(Image.open(png).convert("RGB"))


def page_text(page: Path, tmp_path: Path, fragment: str = "") -> tuple[str, str]:
    """The DOM after the page's scripts ran (MathJax included), and its visible text."""
    dom = chromium(page, tmp_path, "--dump-dom", fragment=fragment).stdout
    text = re.sub(r"<(script|style)\b.*?</\1>", " ", dom, flags=re.S)
    text = re.sub(r"</?(?:p|div|dt|dd|li|h[1-6]|br|td|th|pre|section|nav|header|footer)\b[^>]*>", " ", text)
    text = html.unescape(re.sub(r"<[^>]+>", "", text))          # inline markup: no space added
    return dom, re.sub(r"\s+", " ", text)


def page_requests(netlog: Path) -> list[str]:
    """The URLs a page asked the network for, read from Chromium's ``--log-net-log`` file: the
    requests with an initiator (a page: "null" for a file's opaque origin), not Chromium's own
    background ones ("not an origin")."""
    import json

    d = json.loads(netlog.read_text())
    start = d["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    return [e["params"]["url"] for e in d["events"] if e["type"] == start and "url" in (e.get("params") or {})
            and e["params"].get("initiator") != "not an origin"]


def framed(page: Path, tmp_path: Path, width: int, height: int = 900) -> Path:
    """A page that shows ``page`` in an iframe ``width`` x ``height`` CSS px and prints, in its
    ``<pre id="out">``, the last message the framed page posted to it.  Headless Chromium's
    window is at least 500 px wide, so a phone's 360 px viewport is an iframe's."""
    harness = tmp_path / f"frame-{width}-{page.name}"
    harness.write_text(
        '<!DOCTYPE html><html><head><meta charset="utf-8"></head><body style="margin:0">'
        f'<iframe src="{page.name}" width="{width}" height="{height}" style="border:0;display:block"></iframe>'
        '<pre id="out"></pre><script>window.addEventListener("message", '
        '(e) => { document.getElementById("out").textContent = String(e.data); });</script></body></html>')
    assert harness.parent == page.parent
    return harness

"""Processes of a session, for the stop-signal tests: what outlives a stopped command."""

import time
from pathlib import Path


def session_alive(sid: int) -> list[int]:
    """Processes (not zombies) in session ``sid``."""
    out = []
    for p in Path("/proc").iterdir():
        if not p.name.isdigit():
            continue
        try:
            fields = (p / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(p.name))
    return out


def gone(sid: int, timeout: float = 5.0) -> list[int]:
    """The processes of session ``sid`` still alive after waiting up to ``timeout`` s for them."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and session_alive(sid):
        time.sleep(0.05)
    return session_alive(sid)

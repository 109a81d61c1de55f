"""The one progress bar of every long command (a render's frames, an atlas's runs): on a
terminal a bar with the rate and the time left, redrawn at most five times a second;
otherwise a line at each ``every`` share of the work (a log stays short).  It writes to
stderr (or ``stream``) and is silent when ``enabled`` is False; a stream that fails is the
command line's to guard (``commands.shared.Stream``)."""

from __future__ import annotations

import math
import sys
import time


class Progress:
    """``done`` of ``total`` ``unit`` (``rate_unit``: how the rate is said, e.g. "fps")."""

    def __init__(self, total: int, label: str, unit: str = "runs", rate_unit: str | None = None,
                 enabled: bool = True, every: float = 0.1, stream=None):
        self.total, self.label, self.unit, self.enabled, self.every = max(1, int(total)), label, unit, enabled, every
        self.rate_unit = rate_unit or f"{unit}/s"
        self.stream = stream or sys.stderr
        self.tty = enabled and getattr(self.stream, "isatty", lambda: False)()
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.next_mark = every
        self.done = 0

    def update(self, done: int) -> None:
        """``done`` of the total are finished: redraw the bar (at most five times a second), or
        write a line when another ``every`` share is done."""
        self.done = done
        if not self.enabled:
            return
        now = time.perf_counter()
        rate = done / (now - self.t0) if now > self.t0 else 0.0
        left = (self.total - done) / rate if rate > 0 else math.inf
        frac = done / self.total
        eta = f"{left:5.0f} s left" if math.isfinite(left) else "  ?   s left"
        if self.tty and (now - self.last > 0.2 or done >= self.total):
            self.last = now
            bar = "#" * int(30 * frac)
            self.stream.write(f"\r{self.label} [{bar:<30}] {done}/{self.total} {self.unit} {rate:7.1f} {self.rate_unit} "
                              f"{eta} ")
            if done >= self.total:
                self.stream.write("\n")
            self.stream.flush()
        elif not self.tty and (frac >= self.next_mark or done >= self.total):
            self.stream.write(f"{self.label}: {done}/{self.total} {self.unit} ({100 * frac:.0f} %), "
                              f"{rate:.1f} {self.rate_unit}, {eta}\n")
            self.stream.flush()
            while self.next_mark <= frac:
                self.next_mark += self.every

    def finish(self) -> None:
        """Close the bar's line if the work stopped before its end."""
        if self.enabled and self.tty and self.done < self.total:
            self.stream.write("\n")
            self.stream.flush()

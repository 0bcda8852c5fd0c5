"""Progress of the long loops (basins, speed sweeps, damping and accuracy studies on the
Python side; continuation's branches and curves in the core, which count their points),
reported as :func:`ballbal.scan` reports its own: ``progress=True`` draws a
tqdm bar (``tqdm.auto``: a widget in a notebook, text in a terminal; a line on stderr
without tqdm), a callable ``f(done, total)`` is called after each unit of work."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

from .exceptions import ParameterTypeError

ProgressArg = bool | Callable[[int, int], Any]


def checked(progress: Any) -> ProgressArg:
    """``progress`` if it is True, False or a callable, else an error naming it."""
    if isinstance(progress, bool) or callable(progress):
        return progress
    raise ParameterTypeError("progress", f"must be True, False or a callable f(done, total), "
                             f"got {progress!r:.60}", allowed="bool or callable",
                             value=progress)


class Progress:
    """Counts finished units of work out of ``total`` and shows them as ``progress``
    asks (see the module). Use as a context manager: the bar is closed on the way out,
    Ctrl-C included."""

    def __init__(self, progress: ProgressArg, total: int, desc: str, unit: str = "step",
                 done: int = 0) -> None:
        self.total, self.done, self.desc = total, done, desc
        self.bar: Any = None
        self.fn: Callable[[int, int], Any] | None = None
        progress = checked(progress)
        if callable(progress) and not isinstance(progress, bool):
            self.fn = progress
        elif progress:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, initial=done, unit=unit, desc=desc)
            except ImportError:
                self.fn = self._line

    def _line(self, done: int, total: int) -> None:
        end = "\n" if done >= total else ""
        print(f"\r{self.desc}: {done}/{total}", end=end, file=sys.stderr, flush=True)

    def update(self, n: int = 1) -> None:
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        if self.fn is not None:
            self.fn(self.done, self.total)

    def to(self, done: int) -> None:
        """Moves the count to ``done`` (the core reports how far it is, not by how much
        it moved)."""
        if done > self.done:
            self.update(done - self.done)

    def reporter(self) -> Callable[[int], None] | None:
        """What the core's continuation loops call with their count of points: ``to``,
        or ``None`` when nothing is shown."""
        return self.to if self.bar is not None or self.fn is not None else None

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

"""Progress of long calls (``rendersim.experiment``): a bar in a notebook
(an ipywidgets progress bar, when ipywidgets is installed), a line on a
terminal's standard error, or a function of the caller's.

``experiment(..., progress=...)`` takes:

- ``None`` (the default): a bar in a Jupyter notebook, a line on standard
  error when it is a terminal, nothing otherwise (a script's log stays
  clean);
- ``True``: a bar or a line even when standard error is not a terminal;
- ``False``: nothing;
- a function ``f(done, total)``: called after each run ends (from the
  thread that ran it, with the GIL held). An exception it raises stops the
  runs not yet started and is raised by ``experiment``; so is an interrupt
  (Ctrl-C, a notebook's stop button).

>>> seen = []
>>> report = reporter(lambda done, total: seen.append((done, total)))
>>> report(1, 4); report(4, 4)
>>> seen
[(1, 4), (4, 4)]
>>> reporter(False) is None
True
"""

from __future__ import annotations

import sys
import time
from typing import Callable, Optional, Union

Report = Callable[[int, int], object]
ProgressLike = Union[None, bool, Report]

__all__ = ["ProgressLike", "reporter"]


def _in_notebook() -> bool:
    """Whether this runs in a Jupyter kernel (a notebook or JupyterLab)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except Exception:
        return False
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


class _NotebookBar:
    """An ipywidgets bar with a label: ``done/total runs, elapsed < left``."""

    def __init__(self, widgets, display) -> None:
        self.bar = widgets.IntProgress(min=0, max=1, value=0, bar_style="info")
        self.label = widgets.Label("starting")
        self.started = time.monotonic()
        display(widgets.HBox([self.bar, self.label]))

    def __call__(self, done: int, total: int) -> None:
        self.bar.max = max(total, 1)
        self.bar.value = done
        self.label.value = f"{done}/{total} runs, {_times(self.started, done, total)}"
        if done >= total:
            self.bar.bar_style = "success"


class _TerminalLine:
    """``[#####     ] done/total runs, elapsed < left`` rewritten in place on
    standard error, at most ten times a second, then a newline at the end."""

    def __init__(self) -> None:
        self.started = time.monotonic()
        self.shown = 0.0

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if done < total and now - self.shown < 0.1:
            return
        self.shown = now
        width = 30
        filled = width * done // max(total, 1)
        line = f"\r[{'#' * filled}{' ' * (width - filled)}] {done}/{total} runs, {_times(self.started, done, total)}"
        sys.stderr.write(line + ("\n" if done >= total else ""))
        sys.stderr.flush()


def _times(started: float, done: int, total: int) -> str:
    elapsed = time.monotonic() - started
    if done == 0 or done >= total:
        return f"{elapsed:.1f} s"
    return f"{elapsed:.1f} s < {elapsed * (total - done) / done:.1f} s left"


def reporter(progress: ProgressLike) -> Optional[Report]:
    """The function a call reports its runs to, from its ``progress``
    argument (see the module's documentation); ``None`` for none."""
    if progress is False:
        return None
    if callable(progress) and not isinstance(progress, bool):
        return progress
    if progress is not None and progress is not True:
        raise TypeError(f"progress: expected None, True, False or a function f(done, total), got {progress!r}")
    if _in_notebook():
        try:
            import ipywidgets as widgets  # type: ignore[import-untyped]
            from IPython.display import display  # type: ignore[import-not-found]

            return _NotebookBar(widgets, display)
        except ImportError:
            pass
    if progress is True or sys.stderr.isatty():
        return _TerminalLine()
    return None

"""rendersim's errors, in Python's terms.

- :class:`ModelError` (a ``ValueError``): a model, a ``set`` value, an
  experiment, a mesh or a capture rendersim cannot use, or an argument
  out of range. ``key`` is the dotted model key at fault, ``file`` and
  ``line`` where it stands in a file (``None`` for a value given as an
  argument: the message names the argument, ``set["display.buffers"]``).
- :class:`SimulationError` (a ``ModelError`` and a ``RuntimeError``): a
  run that failed while running (its events or time ran out).
- ``FileNotFoundError`` (Python's own): a model, experiment or capture
  file that does not exist; ``filename`` names it where rendersim knows
  which.

Every rendersim error but ``FileNotFoundError`` is an :class:`Error`:

>>> import rendersim
>>> try:
...     rendersim.run(set={"display.bufers": 3}, frames=10)
... except rendersim.ModelError as e:
...     print(e.key, e.file, str(e).split(":")[0])
display.bufers None set["display.bufers"] = 3 (applied to <embedded default model>)
"""

from __future__ import annotations

import errno
import re
from typing import Optional

__all__ = ["Error", "ModelError", "SimulationError"]


class Error(Exception):
    """Any error rendersim raises of its own (``FileNotFoundError`` aside)."""


class ModelError(Error, ValueError):
    """A model, value, file or argument rendersim cannot use.

    ``key``: the dotted model key at fault; ``file`` and ``line``: where it
    stands (``None`` for a value given as an argument)."""

    def __init__(
        self, message: str, file: Optional[str] = None, line: Optional[int] = None, key: Optional[str] = None
    ) -> None:
        super().__init__(message)
        self.file = file
        self.line = line
        self.key = key


class SimulationError(ModelError, RuntimeError):
    """A run that failed while running (it could not finish)."""


# The command line's words for what Python gives as arguments.
_VALUE_FROM_SET = re.compile(r"value from `--set ([^=`]+)=(.*?)`")
_SET = re.compile(r'--set "((?:[^"\\]|\\.)*?)=((?:[^"\\]|\\.)*)"')
_SET_PLAIN = re.compile(r"--set ([A-Za-z_][\w.\-]*)=(\S+)")
_ASSUME = re.compile(r'--assume "?([A-Za-z_][\w.\-]*)=([^":]*)"?')
_OPTION = re.compile(r"--(seed|frames) (\S+)")


def python_terms(message: str) -> str:
    """The command line's message with its options written as the Python
    arguments that gave them (``--set k=v`` as ``set["k"] = v``)."""
    message = _VALUE_FROM_SET.sub(lambda m: f'set["{m[1]}"] = {m[2]}', message)
    message = _SET.sub(lambda m: f'set["{m[1]}"] = {m[2]}'.replace('\\"', '"'), message)
    message = _SET_PLAIN.sub(lambda m: f'set["{m[1]}"] = {m[2]}', message)
    message = _ASSUME.sub(lambda m: f'assumes "{m[1]}={m[2]}"', message)
    return _OPTION.sub(lambda m: f"{m[1]}={m[2]}", message)


def from_native(e: Exception) -> Exception:
    """The native module's error as the one Python code expects."""
    message = python_terms(str(e))
    kind = getattr(e, "kind", "model")
    if kind == "missing":
        message = message.replace(" (os error 2)", "")
        filename = getattr(e, "filename", None)
        if filename is None:
            return FileNotFoundError(errno.ENOENT, message)
        return FileNotFoundError(errno.ENOENT, message, filename)
    file = getattr(e, "file", None)
    if file is not None and file.startswith("value from `--"):
        file = None  # given as an argument, not written in a file
    cls = SimulationError if kind == "simulation" else ModelError
    return cls(message, file=file, line=getattr(e, "line", None), key=getattr(e, "key", None))

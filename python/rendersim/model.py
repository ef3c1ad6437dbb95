"""A model as a Python value: :class:`Model`, and what every function of
the package takes as ``model``.

A ``model`` argument is any of:

- ``None``: the embedded default model;
- a path (``str`` without a newline or ``=``, or ``os.PathLike``): a model
  file, its relative paths read from its folder;
- TOML text (``str`` with a newline or ``=``), such as ``Run.model``: its
  relative paths read from the working folder;
- a ``dict`` of the model's tables (``{"display": {"buffers": 3}}``);
- a :class:`Model`, with the changes made to it.

>>> import rendersim
>>> m = rendersim.Model.load("models/fixed.toml").set("display.buffers", 3)
>>> m                                   # doctest: +ELLIPSIS
<rendersim.Model frame_pipeline from .../fixed.toml, changed: display.buffers=3>
>>> m.to_dict()["display"]["buffers"]
3
>>> rendersim.run(m, frames=20).summary["frames"]
20
"""

from __future__ import annotations

import json
import os
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

from . import _native
from .errors import ModelError, from_native

__all__ = ["Model"]

ModelLike = Union[None, str, "os.PathLike[str]", Mapping[str, Any], "Model"]


def _toml_value(value: Any, where: str) -> str:
    from . import to_toml

    try:
        return to_toml(value)
    except ModelError as e:
        raise ModelError(f"{where}: {e}", key=where) from None


def dict_to_toml(tables: Mapping[str, Any], prefix: str = "") -> str:
    """A dict of a model's tables as TOML text: plain values first, then
    each table as ``[name]`` and each list of tables as ``[[name]]``."""
    lines: list[str] = []
    later: list[str] = []
    for k, v in tables.items():
        if not isinstance(k, str) or not k:
            raise ModelError(f"model: key {k!r} in {prefix or 'the model'} is not a name")
        name = f"{prefix}.{k}" if prefix else k
        quoted = json.dumps(k) if not k.replace("_", "").replace("-", "").isalnum() else k
        full = f"{prefix}.{quoted}" if prefix else quoted
        if isinstance(v, Mapping):
            later.append(f"\n[{full}]\n" + dict_to_toml(v, full))
        elif isinstance(v, (list, tuple)) and v and all(isinstance(x, Mapping) for x in v):
            for x in v:
                later.append(f"\n[[{full}]]\n" + dict_to_toml(x, full))
        else:
            lines.append(f"{quoted} = {_toml_value(v, name)}")
    return "\n".join(lines) + ("\n" if lines else "") + "".join(later)


def model_args(model: ModelLike, argument: str = "model") -> Tuple[Optional[str], Optional[str], list]:
    """``model`` as the native calls take it: (file path, TOML text, the
    ``--set`` assignments of a :class:`Model`'s changes)."""
    if model is None:
        return None, None, []
    if isinstance(model, Model):
        return model._path, model._text, model._assignments()
    if isinstance(model, Mapping):
        return None, dict_to_toml(model), []
    if isinstance(model, str):
        if "\n" in model or "=" in model:
            return None, model, []
        return model, None, []
    if isinstance(model, os.PathLike):
        return os.fspath(model), None, []
    raise TypeError(
        f"{argument}: expected a path, TOML text, a dict or a rendersim.Model, got {type(model).__name__}"
    )


class Model:
    """A model: a file, TOML text or a dict, and the changes made to it.

    Made by :meth:`load`, :meth:`from_toml` or :meth:`from_dict` (or
    ``Model()``, the embedded default). :meth:`set` returns a new model
    with one more change, checked at once (a misspelt key raises
    :class:`ModelError` there, naming it). Every function that takes a
    ``model`` takes a ``Model``."""

    _path: Optional[str]
    _text: Optional[str]
    _changes: dict
    _resolved: Tuple[str, str, str, str]

    def __init__(self, source: ModelLike = None) -> None:
        if isinstance(source, Model):
            self._path, self._text, self._changes = source._path, source._text, dict(source._changes)
        else:
            path, text, _ = model_args(source, "Model")
            self._path, self._text = path, text
            self._changes = {}
        self._resolve()

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "Model":
        """The model file at ``path`` (``FileNotFoundError`` if there is none)."""
        m = cls.__new__(cls)
        m._path, m._text, m._changes = os.fspath(path), None, {}
        m._resolve()
        return m

    @classmethod
    def from_toml(cls, text: str) -> "Model":
        """A model written as TOML text (``Run.model`` is one)."""
        m = cls.__new__(cls)
        m._path, m._text, m._changes = None, str(text), {}
        m._resolve()
        return m

    @classmethod
    def from_dict(cls, tables: Mapping[str, Any]) -> "Model":
        """A model as a dict of its tables, ``{"display": {"buffers": 3}}``."""
        return cls.from_toml(dict_to_toml(tables))

    def set(self, key: str, value: Any) -> "Model":
        """A new model with ``key`` (dotted: ``"display.buffers"``) set to
        ``value`` (a Python value; a ``str`` is a string)."""
        if not isinstance(key, str) or not key.strip():
            raise ModelError(f"set: key {key!r} is not a dotted model key")
        m = Model(self)
        m._changes[key] = value
        m._resolve()
        return m

    @property
    def system(self) -> str:
        """The system the model runs (``frame_pipeline``, ``walkthrough``, ...)."""
        return self._resolved[1]

    @property
    def name(self) -> str:
        """The file it came from, or ``<model text>``, or the embedded default's name."""
        return self._resolved[0]

    @property
    def changes(self) -> dict:
        """The changes made by :meth:`set`, in order."""
        return dict(self._changes)

    def to_toml(self) -> str:
        """The model with its changes as TOML text (a model file)."""
        return self._resolved[2]

    def to_dict(self) -> dict:
        """The model with its changes as a dict of its tables."""
        return json.loads(self._resolved[3])

    def __repr__(self) -> str:
        changed = ", ".join(f"{k}={v!r}" for k, v in self._changes.items())
        return f"<rendersim.Model {self.system} from {self.name}" + (f", changed: {changed}>" if changed else ">")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Model) and self.to_dict() == other.to_dict()

    def _assignments(self) -> list:
        return [f"{k}={_toml_value(v, k)}" for k, v in self._changes.items()]

    def _resolve(self) -> None:
        try:
            self._resolved = _native.resolve(self._path, self._text, self._assignments())
        except _native.ModelError as e:
            raise from_native(e) from None


def join_sets(model_sets: Sequence[str], sets: Sequence[str]) -> list:
    """A model's own changes, then the call's."""
    return list(model_sets) + list(sets)

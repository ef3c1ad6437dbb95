"""rendersim from Python: a discrete-event simulator of GPU rendering
pipelines and latency.

The functions here call the same library as the ``rendersim`` command line
(no subprocess), release the GIL while they simulate, and give results as
dicts and pandas DataFrames:

>>> import rendersim
>>> r = rendersim.run(set={"display.buffers": 3}, frames=120)
>>> r.summary["metrics"]["frame_time_ms"]["mean"]     # doctest: +SKIP
16.666666667
>>> r.frames[["Frame", "MsUntilDisplayed"]].head()    # doctest: +SKIP

Errors raise :class:`ModelError` (a ``ValueError``) with the command line's
message in Python's terms and, where it names them, ``file``, ``line`` and
``key``; :class:`SimulationError` for a run that failed while running; and
``FileNotFoundError`` for a file that does not exist (``rendersim.errors``).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Mapping, Optional, Sequence, Union

from . import _native
from .errors import Error, ModelError, SimulationError, from_native
from .model import Model, ModelLike, model_args

__all__ = [
    "Error",
    "ModelError",
    "SimulationError",
    "Model",
    "Run",
    "ExperimentResult",
    "ReplayResult",
    "run",
    "experiment",
    "vcache",
    "isolate",
    "replay",
    "timeline",
    "perceived_speed",
    "to_toml",
    "__version__",
]

__version__: str = _native.version()[0].split(" ", 1)[1]

PathLike = Union[str, "os.PathLike[str]"]


@contextlib.contextmanager
def _native_errors() -> Iterator[None]:
    """The native module's errors raised as Python's (``rendersim.errors``)."""
    try:
        yield
    except _native.ModelError as e:
        raise from_native(e) from None


def to_toml(value: Any) -> str:
    """A Python value as a TOML literal, for ``set={...}``: strings quoted,
    booleans ``true``/``false``, lists as arrays, dicts as inline tables.
    (The command line's ``--set`` takes text that is not TOML as a string;
    here a Python ``str`` is always a string: ``"17ms"``, ``"fifo"``.)"""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value) or math.isinf(value):
            raise ModelError(f"set: {value!r} is not a number a model can hold")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(to_toml(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {to_toml(v)}" for k, v in value.items()) + " }"
    raise ModelError(f"set: a {type(value).__name__} ({value!r}) has no TOML form")


def _sets(set: Optional[Mapping[str, Any]], sets: Sequence[str] = ()) -> list[str]:
    """`sets` (``"key=value"`` strings, as the command line's ``--set``:
    the value is TOML, or a string if it is not), then ``set``."""
    if isinstance(sets, str) or not all(isinstance(s, str) for s in sets):
        raise ModelError(f"sets: expected a list of \"key=value\" strings, got {sets!r}")
    out = list(sets)
    if set is None:
        return out
    if not isinstance(set, Mapping):
        raise ModelError(f"set: expected a dict of dotted keys to values, got {type(set).__name__}")
    for k, v in set.items():
        if not isinstance(k, str) or not k.strip():
            raise ModelError(f"set: key {k!r} is not a dotted model key")
        out.append(f"{k}={to_toml(v)}")
    return out


def _path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)


def _given(p: PathLike) -> str:
    return os.fspath(p)


def _command(name: str, **kwargs: Any) -> list[str]:
    shown = ", ".join(f"{k}={v!r}" for k, v in kwargs.items() if v not in (None, {}, [], ()))
    return ["python", f"rendersim.{name}({shown})"]


# Columns of 0/1 that mean yes or no: read as booleans.
_FLAGS = ("Displayed", "Dropped")


def _csv(text: str):
    """A frames-like CSV as a DataFrame: ``NA`` as NaN,
    ``Displayed``/``Dropped`` as booleans."""
    import pandas as pd

    if not text:
        return pd.DataFrame()
    df = pd.read_csv(io.StringIO(text), na_values=["NA"], keep_default_na=False)
    for flag in _FLAGS:
        if flag in df.columns and df[flag].dtype.kind in "iu" and df[flag].isin((0, 1)).all():
            df[flag] = df[flag].astype(bool)
    return df


def _frames(native: Any):
    """A run's frames as a DataFrame, from the numbers the native module
    holds (no CSV text in between); the same frame ``_csv`` reads from its
    ``frames.csv``, column for column and bit for bit."""
    import numpy as np
    import pandas as pd

    table = native.table()
    if table is None:
        return _csv(native.csv())
    text, kinds, names, values, rows = table
    numbers = np.frombuffer(values, dtype="<f8").reshape(rows, len(names))
    columns: dict = {}
    for name, value in text:
        # As a CSV reader types a column holding one value on every row.
        v: Any = int(value) if value.lstrip("-").isdigit() else value
        columns[name] = pd.Series([v], dtype=None).repeat(rows).reset_index(drop=True)
    generated = np.frombuffer(kinds, dtype=np.uint8).astype(bool)
    columns["FrameType"] = pd.Series(np.where(generated, "Generated", "Application"), dtype="str")
    for i, name in enumerate(names):
        col = numbers[:, i]
        if name in _FLAGS:
            columns[name] = col.astype(bool)
        elif name == "Frame":
            columns[name] = col.astype(np.int64)
        else:
            columns[name] = col.copy()
    return pd.DataFrame(columns)


@dataclass
class Run:
    """One model run: ``summary`` (the JSON summary as a dict, as
    ``rendersim run --json``), ``frames`` (``frames.csv``: one row a frame,
    PresentMon 2 columns) and ``model`` (the resolved model as TOML text:
    written to a file, it reproduces the run)."""

    summary: dict
    frames: Any
    model: str
    notes: list = field(default_factory=list)
    summary_json: str = field(default="", repr=False)
    native: Any = field(default=None, repr=False)

    @property
    def frames_csv(self) -> str:
        """The run's ``frames.csv`` as the command line writes it (made
        when asked: the DataFrame does not go through it)."""
        return "" if self.native is None else self.native.csv()

    def save(self, out: PathLike) -> Path:
        """Writes ``summary.json``, ``frames.csv`` and ``model.toml`` into
        the folder ``out`` (made if missing), the bytes ``rendersim run
        --out`` writes; returns the folder."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "summary.json").write_text(self.summary_json)
        (out / "frames.csv").write_text(self.frames_csv)
        (out / "model.toml").write_text(self.model)
        return out

    def __repr__(self) -> str:
        m = self.summary.get("metrics", {}).get("frame_time_ms", {}).get("mean")
        return f"<rendersim.Run {self.summary.get('model')!r}: {self.summary.get('frames')} frames, frame time {m} ms>"


def run(
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    seed: int = 1,
    frames: Optional[int] = None,
    sets: Sequence[str] = (),
) -> Run:
    """Runs a model (a file, TOML text such as ``Run.model``, a dict of its
    tables or a :class:`Model`; the embedded default model when ``model``
    is None) with ``set`` patches (``{"display.buffers": 3}``) and ``sets``
    (``["display.buffers=3"]``, the command line's ``--set`` text), the
    master ``seed`` and, when given, ``frames`` frames.

    Raises :class:`ModelError` for a model it cannot use."""
    if seed is not None and (not isinstance(seed, int) or seed < 0):
        raise ModelError(f"seed: expected a whole number >= 0, got {seed!r}")
    if frames is not None and (not isinstance(frames, int) or frames < 0):
        raise ModelError(f"frames: expected a whole number >= 0, got {frames!r}")
    path, text, own = model_args(model)
    shown = repr(model) if isinstance(model, Model) else (path or ("<model text>" if text else None))
    command = _command("run", model=shown, set=dict(set or {}), sets=list(sets), seed=seed, frames=frames)
    with _native_errors():
        summary, native, model_text, notes = _native.run(path, text, own + _sets(set, sets), seed, frames, command)
        table = _frames(native)
    return Run(
        summary=json.loads(summary),
        frames=table,
        model=model_text,
        notes=list(notes),
        summary_json=summary,
        native=native,
    )


@dataclass
class ExperimentResult:
    """An experiment's results, written to ``out`` as ``rendersim experiment
    --out`` writes them: ``points`` and ``runs`` (DataFrames of
    ``points.csv`` and ``runs.csv``), ``plots`` (paths of the PNG and SVG
    plots), ``report`` (``report.md``), ``checks_failed``."""

    name: str
    out: Path
    points: Any
    runs: Any
    plots: list
    report: str
    checks_failed: int
    wall_seconds: float

    def __repr__(self) -> str:
        return (
            f"<rendersim.ExperimentResult {self.name!r}: {len(self.points)} points, "
            f"{self.checks_failed} checks failed, in {str(self.out)!r}>"
        )


def experiment(
    path: PathLike,
    set: Optional[Mapping[str, Any]] = None,
    out: Optional[PathLike] = None,
    force: bool = False,
    sets: Sequence[str] = (),
) -> ExperimentResult:
    """Runs an experiment file (sweeps, replications, checks, plots) with
    ``set`` added to its ``[set]`` table, into ``out`` (default
    ``out/<name>``, as the command line). A failed reference check does not
    raise: see ``checks_failed``."""
    import pandas as pd

    command = _command("experiment", path=_path(path), set=dict(set or {}), sets=list(sets), out=_path(out))
    with _native_errors():
        written, result = _native.experiment(_given(path), _sets(set, sets), _path(out), bool(force), command)
    res = json.loads(result)
    out_dir = Path(written)
    files = [out_dir / f for f in res["files"]]
    return ExperimentResult(
        name=res["name"],
        out=out_dir,
        points=pd.read_csv(out_dir / "points.csv"),
        runs=pd.read_csv(out_dir / "runs.csv"),
        plots=[f for f in files if f.suffix in (".png", ".svg")],
        report=(out_dir / "report.md").read_text(),
        checks_failed=res["checks_failed"],
        wall_seconds=res["wall_seconds"],
    )


def vcache(mesh: str, policy: str) -> dict:
    """A post-transform vertex cache over a mesh's index buffer (``mesh``:
    ``grid:WxH``, ``random:T:V:SEED``, a ``.obj`` file, ...; ``policy``:
    ``fifo:32``, ``lru:16``, ``nvidia``, ...): triangles, indices, unique
    and transformed vertices, ACMR and ATVR."""
    with _native_errors():
        return json.loads(_native.vcache(str(mesh), str(policy)))


def isolate(
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    factor: float = 0.5,
    keep_vsync: bool = False,
    tie_tolerance: float = 0.02,
    sets: Sequence[str] = (),
    fidelity: str = "draw",
) -> dict:
    """Isolates the bottleneck (paper 004 section 4.1): the frame time with
    the CPU, GPU front end, geometry and raster load each reduced by
    ``factor`` in turn; returns the variants and the verdict. ``fidelity``:
    ``"draw"`` (default, as the command line), ``"triangle"`` or
    ``"model"`` (the model file's own). The dict has the keys of
    ``rendersim isolate --json``: ``frames`` each variant ran, and ``note``
    when a run too short to judge from was lengthened."""
    path, text, own = model_args(model)
    with _native_errors():
        out = _native.isolate(
            path, text, own + _sets(set, sets), float(factor), bool(keep_vsync), float(tie_tolerance), str(fidelity)
        )
    return json.loads(out)


@dataclass
class ReplayResult:
    """A PresentMon capture replayed through the frame pipeline:
    ``summary`` (the ``replay`` object of ``rendersim replay --json``),
    ``comparison`` (measured against predicted per frame), ``frames`` (the
    replay as captured, PresentMon columns) and ``whatif_frames`` (with a
    what-if, its frames; else None)."""

    summary: dict
    comparison: Any
    frames: Any
    whatif_frames: Any


def replay(
    capture: PathLike,
    app: Optional[str] = None,
    swapchain: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
    assume: Optional[Mapping[str, Any]] = None,
    sets: Sequence[str] = (),
    assumes: Sequence[str] = (),
) -> ReplayResult:
    """Replays a PresentMon CSV capture; ``set`` is a what-if on the
    display and CPU (``{"display.refresh": "120Hz"}``), ``assume`` what the
    capture does not say (``{"display.buffers": 3}``)."""
    with _native_errors():
        summary, comparison, frames, whatif = _native.replay(
            _given(capture), app, swapchain, _sets(set, sets), _sets(assume, assumes)
        )
    return ReplayResult(
        summary=json.loads(summary),
        comparison=_csv(comparison),
        frames=_csv(frames),
        whatif_frames=_csv(whatif) if whatif else None,
    )


def timeline(
    out: PathLike,
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    frames: int = 6,
    first: int = 0,
    sets: Sequence[str] = (),
) -> dict:
    """Draws paper 000 Figure 4 (one lane a unit, frames by colour,
    vertical blanks marked) for ``frames`` frames from frame ``first`` into
    ``out`` (``.png`` or ``.svg``), as ``rendersim timeline``; returns the
    frames and the time range drawn (ms)."""
    path, text, own = model_args(model)
    with _native_errors():
        f0, f1, t0, t1 = _native.timeline(path, text, own + _sets(set, sets), int(first), int(frames), _given(out))
    return {"out": Path(out), "frames": (f0, f1), "range_ms": (t0, t1)}


def perceived_speed(
    model: PathLike,
    out: PathLike,
    set: Optional[Mapping[str, Any]] = None,
    around: int = 8,
    sets: Sequence[str] = (),
) -> dict:
    """Paper 000 Figure 6 from a walkthrough model: the perceived speed per
    displayed refresh around the first frame skip, drawn to ``out`` (its
    ``.png`` and ``.svg``), as ``rendersim perceived-speed``."""
    with _native_errors():
        skip, r0, r1, skips = _native.perceived_speed(_given(model), _sets(set, sets), int(around), _given(out))
    return {"out": Path(out), "first_skip": skip, "refreshes": (r0, r1), "skips": skips}

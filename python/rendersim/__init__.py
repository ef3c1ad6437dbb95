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
from .progress import ProgressLike, reporter

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


def _frames(table: Any):
    """A frames table from the native module (a run's or a replay's; no
    CSV text in between) as a DataFrame: the same frame ``_csv`` reads from
    its ``frames.csv``, column for column and bit for bit."""
    import numpy as np
    import pandas as pd

    text, kinds, names, values, rows = table
    # Column by column in a bytearray: each column a writable view, no copy.
    numbers = np.frombuffer(values, dtype="<f8").reshape(len(names), rows)
    columns: dict = {}
    for name, value in text:
        # As a CSV reader types a column holding one value on every row.
        v: Any = int(value) if value.lstrip("-").isdigit() else value
        columns[name] = pd.Series([v], dtype=None).repeat(rows).reset_index(drop=True)
    generated = np.frombuffer(kinds, dtype=np.uint8).astype(bool)
    columns["FrameType"] = pd.Series(np.where(generated, "Generated", "Application"), dtype="str")
    for name, col in zip(names, numbers):
        if name in _FLAGS:
            columns[name] = col.astype(bool)
        elif name == "Frame":
            columns[name] = col.astype(np.int64)
        else:
            columns[name] = col
    return pd.DataFrame(columns, copy=False)


# The comparison's yes-or-no columns.
_COMPARISON_FLAGS = ("Displayed", "PredictedDisplayed", "WhatIfDisplayed")


def _numbers(table: Any):
    """A table of numbers from the native module (the replay's comparison)
    as a DataFrame: ``Line`` as integers, the yes-or-no columns
    (``Displayed``, ``PredictedDisplayed``, ``WhatIfDisplayed``) as booleans (pandas' nullable ``boolean`` where a
    row has no value), the rest as floats (NaN where a value does not
    exist)."""
    import numpy as np
    import pandas as pd

    names, values, rows = table
    numbers = np.frombuffer(values, dtype="<f8").reshape(len(names), rows)
    columns: dict = {}
    for name, col in zip(names, numbers):
        missing = np.isnan(col)
        if name == "Line" and not missing.any():
            columns[name] = col.astype(np.int64)
        elif name in _COMPARISON_FLAGS:
            flags = pd.array(col == 1, dtype="boolean")
            flags[missing] = pd.NA
            columns[name] = flags if missing.any() else col == 1
        else:
            columns[name] = col
    return pd.DataFrame(columns, copy=False)


# Units a sweep value may carry, to the unit its column is given in.
_TIME_MS = {"s": 1e3, "ms": 1.0, "us": 1e-3, "µs": 1e-3, "μs": 1e-3, "ns": 1e-6, "ps": 1e-9}
_RATE_HZ = {"Hz": 1.0, "hz": 1.0, "kHz": 1e3, "khz": 1e3, "MHz": 1e6}


def _unit_number(v: Any) -> Optional[tuple[float, str]]:
    """``"12.5ms"`` as (12.5, "ms"); ``"0"`` as (0.0, ""); None for text
    that is not a number with a unit."""
    if not isinstance(v, str):
        return None
    t = v.strip()
    i = 0
    while i < len(t) and (t[i].isdigit() or t[i] in ".+-_"):
        i += 1
    try:
        number = float(t[:i].replace("_", ""))
    except ValueError:
        return None
    return (number, t[i:].strip()) if math.isfinite(number) else None


def _typed_sweeps(df: Any, keys: Sequence[str]) -> Any:
    """Swept columns whose values are durations (``"10ms"``) or rates
    (``"60Hz"``) as numbers, renamed with their unit as the summary's names
    are (``workload.gpu`` -> ``workload.gpu_ms``, ``display.refresh`` ->
    ``display.refresh_hz``); ``df.attrs["units"]`` maps each to its unit
    and ``df.attrs["swept"]`` lists the swept columns. Columns of other
    values (numbers, names, paths, a mix) are left as they are."""
    units: dict = {}
    swept: list = []
    renames: dict = {}
    for key in keys:
        if key not in df.columns:
            continue
        parsed = [_unit_number(v) for v in df[key]]
        swept.append(key)
        if not parsed or any(p is None for p in parsed):
            continue
        given = {u for _, u in parsed if u}  # type: ignore[misc]
        for table, unit, suffix in ((_TIME_MS, "ms", "_ms"), (_RATE_HZ, "Hz", "_hz")):
            # "0" is a duration of any unit; a rate needs one.
            if given and given <= table.keys() and (unit == "ms" or all(u for _, u in parsed)):  # type: ignore[misc]
                df[key] = [n * table.get(u, 1.0) for n, u in parsed]  # type: ignore[misc]
                renames[key] = key + suffix
                units[key + suffix] = unit
                swept[-1] = key + suffix
                break
    df = df.rename(columns=renames)
    df.attrs["units"] = units
    df.attrs["swept"] = swept
    return df


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

    def save(self, out: PathLike, force: bool = False) -> Path:
        """Writes ``summary.json``, ``frames.csv`` and ``model.toml`` into
        the folder ``out`` as ``rendersim run --out`` does: the same files,
        written beside it and swapped in whole, so ``out`` holds the old
        run or the new one, never a mix; the folder is marked as a run's,
        so this and the command line may write there again. A folder
        holding other files is refused (:class:`ModelError`), and an
        experiment's or a replay's results unless ``force``. Returns the
        folder."""
        if self.native is None:
            raise ModelError("save: this Run holds no frames (made by hand?); run the model again")
        with _native_errors():
            return Path(self.native.save(_given(out), self.summary_json, self.model, bool(force)))

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
        numbers = native.table()
        table = _frames(numbers) if numbers is not None else _csv(native.csv())
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
    ``points.csv`` and ``runs.csv``, swept durations and rates as numbers
    with their unit in the column's name, ``workload.gpu_ms``, and in
    ``attrs["units"]``; ``points_long``, the points in tidy form),
    ``plots`` (paths of the PNG and SVG plots), ``report``
    (``report.md``), ``checks_failed``."""

    name: str
    out: Path
    points: Any
    runs: Any
    plots: list
    report: str
    checks_failed: int
    wall_seconds: float

    @property
    def points_long(self) -> Any:
        """``points`` in tidy (long) form: one row per point, metric and
        statistic, with the point's swept values: columns ``point``, the
        swept keys, ``metric`` (``metrics.frame_time_ms.mean``, or a
        derived value's name), ``stat`` (``mean``, ``ci_low``, ``ci_high``,
        ``n``; ``derived`` for a derived value) and ``value``; what
        ``groupby``, ``pivot`` and seaborn take."""
        p = self.points
        ids = ["point"] + [c for c in p.attrs.get("swept", []) if c in p.columns]
        measured = [c for c in p.columns if c not in ids]
        long = p.melt(id_vars=ids, value_vars=measured, var_name="metric:stat", value_name="value")
        named = long["metric:stat"].astype(str)
        has_stat = named.str.contains(":", regex=False)
        parts = named.str.rsplit(":", n=1, expand=True).reindex(columns=[0, 1])
        long["metric"] = parts[0].where(has_stat, named)
        long["stat"] = parts[1].where(has_stat, "derived")
        long = long[ids + ["metric", "stat", "value"]]
        long.attrs = dict(p.attrs)
        return long

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
    progress: ProgressLike = None,
) -> ExperimentResult:
    """Runs an experiment file (sweeps, replications, checks, plots) with
    ``set`` added to its ``[set]`` table, into ``out`` (default
    ``out/<name>``, as the command line). A failed reference check does not
    raise: see ``checks_failed``.

    ``progress``: ``None`` shows a bar in a notebook or on a terminal,
    ``False`` nothing, ``True`` always; a function ``f(done, total)`` is
    called after each run (``rendersim.progress``). An exception it raises,
    or an interrupt (Ctrl-C), stops the runs not yet started and is raised
    here; ``out`` then keeps what it held before."""
    import pandas as pd

    report = reporter(progress)
    command = _command("experiment", path=_path(path), set=dict(set or {}), sets=list(sets), out=_path(out))
    with _native_errors():
        written, result = _native.experiment(_given(path), _sets(set, sets), _path(out), bool(force), command, report)
    res = json.loads(result)
    out_dir = Path(written)
    files = [out_dir / f for f in res["files"]]
    swept = res.get("swept", [])
    return ExperimentResult(
        name=res["name"],
        out=out_dir,
        points=_typed_sweeps(pd.read_csv(out_dir / "points.csv"), swept),
        runs=_typed_sweeps(pd.read_csv(out_dir / "runs.csv"), swept),
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
    ``comparison`` (measured against predicted per frame: ``Line`` of the
    capture, times in ms, ``Displayed``-like columns as booleans),
    ``frames`` (the replay as captured, PresentMon columns, as
    ``Run.frames``) and ``whatif_frames`` (with a what-if, its frames;
    else None). The tables come from the replay's numbers, not from CSV
    text."""

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
        comparison=_numbers(comparison),
        frames=_frames(frames),
        whatif_frames=_frames(whatif) if whatif is not None else None,
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

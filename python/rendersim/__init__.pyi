"""Type stubs of the rendersim package (see its docstrings)."""

import os
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

import pandas as pd

from .errors import Error as Error
from .errors import ModelError as ModelError
from .errors import SimulationError as SimulationError
from .model import Model as Model
from .model import ModelLike as ModelLike

__version__: str
PathLike = Union[str, os.PathLike[str]]

def to_toml(value: Any) -> str: ...

class Run:
    summary: dict[str, Any]
    frames: pd.DataFrame
    model: str
    notes: list[str]
    summary_json: str
    frames_csv: str
    def save(self, out: PathLike) -> Path: ...

def run(
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    seed: int = 1,
    frames: Optional[int] = None,
    sets: Sequence[str] = (),
) -> Run: ...

class ExperimentResult:
    name: str
    out: Path
    points: pd.DataFrame
    runs: pd.DataFrame
    plots: list[Path]
    report: str
    checks_failed: int
    wall_seconds: float

def experiment(
    path: PathLike,
    set: Optional[Mapping[str, Any]] = None,
    out: Optional[PathLike] = None,
    force: bool = False,
    sets: Sequence[str] = (),
) -> ExperimentResult: ...
def vcache(mesh: str, policy: str) -> dict[str, Any]: ...
def isolate(
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    factor: float = 0.5,
    keep_vsync: bool = False,
    tie_tolerance: float = 0.02,
    sets: Sequence[str] = (),
    fidelity: str = "draw",
) -> dict[str, Any]: ...

class ReplayResult:
    summary: dict[str, Any]
    comparison: pd.DataFrame
    frames: pd.DataFrame
    whatif_frames: Optional[pd.DataFrame]

def replay(
    capture: PathLike,
    app: Optional[str] = None,
    swapchain: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
    assume: Optional[Mapping[str, Any]] = None,
    sets: Sequence[str] = (),
    assumes: Sequence[str] = (),
) -> ReplayResult: ...
def timeline(
    out: PathLike,
    model: ModelLike = None,
    set: Optional[Mapping[str, Any]] = None,
    frames: int = 6,
    first: int = 0,
    sets: Sequence[str] = (),
) -> dict[str, Any]: ...
def perceived_speed(
    model: PathLike,
    out: PathLike,
    set: Optional[Mapping[str, Any]] = None,
    around: int = 8,
    sets: Sequence[str] = (),
) -> dict[str, Any]: ...

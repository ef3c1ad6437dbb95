"""rendersim's native module (PyO3); use the functions of ``rendersim``."""

from typing import Callable, Optional, final

# (text columns as (name, value), generated-frame flags (one byte a row),
# numeric column names, their values column by column as little-endian f64
# bytes, rows)
_FramesTable = tuple[list[tuple[str, str]], bytes, list[str], bytearray, int]
# (column names, values column by column as little-endian f64 bytes, rows)
_NumberTable = tuple[list[str], bytearray, int]

__all__ = [
    "ModelError",
    "RunFrames",
    "run",
    "resolve",
    "experiment",
    "vcache",
    "isolate",
    "replay",
    "timeline",
    "perceived_speed",
    "version",
]

class ModelError(ValueError):
    file: Optional[str]
    line: Optional[int]
    key: Optional[str]
    kind: str  # "model", "missing" or "simulation"
    filename: Optional[str]

@final
class RunFrames:
    def table(self) -> Optional[_FramesTable]: ...
    def csv(self) -> str: ...
    def save(self, out: str, summary: str, model: str, force: bool = False) -> str: ...

def run(
    model: Optional[str], text: Optional[str], sets: list[str], seed: Optional[int], frames: Optional[int], command: list[str]
) -> tuple[str, RunFrames, str, list[str]]: ...
def resolve(model: Optional[str], text: Optional[str], sets: list[str]) -> tuple[str, str, str, str]: ...
def experiment(
    path: str,
    sets: list[str],
    out: Optional[str],
    force: bool,
    command: list[str],
    progress: Optional[Callable[[int, int], object]] = None,
) -> tuple[str, str]: ...
def vcache(mesh: str, policy: str) -> str: ...
def isolate(
    model: Optional[str],
    text: Optional[str],
    sets: list[str],
    factor: float, keep_vsync: bool, tie_tolerance: float, fidelity: str
) -> str: ...
def replay(
    capture: str, app: Optional[str], swapchain: Optional[str], sets: list[str], assume: list[str]
) -> tuple[str, _NumberTable, _FramesTable, Optional[_FramesTable]]: ...
def timeline(
    model: Optional[str], text: Optional[str], sets: list[str], first: int, frames: int, out: str
) -> tuple[int, int, float, float]: ...
def perceived_speed(model: str, sets: list[str], around: int, out: str) -> tuple[Optional[int], int, int, int]: ...
def version() -> tuple[str, Optional[str]]: ...

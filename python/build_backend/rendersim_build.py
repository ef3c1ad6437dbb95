"""The Python package's build backend: maturin's, with two habits for a checkout.

``pip install ./python`` calls these hooks (PEP 517); each is maturin's own,
and the two that compile (``build_wheel``, ``build_editable``) run it so:

- **The checkout's build is shared.** Built from a rendersim checkout, cargo
  uses the checkout's ``target/`` folder (unless ``CARGO_TARGET_DIR`` names
  another), so the crates that ``cargo build --release`` already compiled
  for the command line are reused, not compiled a second time into
  ``python/target``. Built from anywhere else (an sdist unpacked in a
  temporary folder), nothing changes.
- **Progress on a terminal.** pip shows a build backend's output only with
  ``-v``; without it a build of minutes looks hung. When the process has a
  terminal, cargo's output (and its progress bar) goes to it; in a pipe, a
  log or CI, nothing is added.
"""

from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path
from typing import Iterator

import maturin

# The hooks that compile nothing are maturin's as they are.
get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
get_requires_for_build_sdist = maturin.get_requires_for_build_sdist
prepare_metadata_for_build_wheel = maturin.prepare_metadata_for_build_wheel
build_sdist = maturin.build_sdist
if hasattr(maturin, "get_requires_for_build_editable"):
    get_requires_for_build_editable = maturin.get_requires_for_build_editable
if hasattr(maturin, "prepare_metadata_for_build_editable"):
    prepare_metadata_for_build_editable = maturin.prepare_metadata_for_build_editable

_PYTHON = Path(__file__).resolve().parent.parent


def checkout_target() -> Path | None:
    """The checkout's ``target/`` when ``python/`` sits in a rendersim checkout."""
    root = _PYTHON.parent
    manifest = root / "Cargo.toml"
    try:
        text = manifest.read_text(encoding="utf-8")
    except OSError:
        return None
    if 'name = "rendersim"' in text and (root / "crates" / "models" / "Cargo.toml").is_file():
        return root / "target"
    return None


@contextlib.contextmanager
def _checkout_habits() -> Iterator[None]:
    saved_env = os.environ.get("CARGO_TARGET_DIR")
    target = checkout_target() if saved_env is None else None
    if target is not None:
        os.environ["CARGO_TARGET_DIR"] = str(target)
    try:
        tty = os.open("/dev/tty", os.O_WRONLY | os.O_NOCTTY)
    except OSError:
        tty = None
    saved_fd = None
    started = time.monotonic()
    if tty is not None:
        saved_fd = os.dup(2)
        os.dup2(tty, 2)
        shared = f"sharing {target}" if target is not None else f"in {saved_env or 'python/target'}"
        os.write(
            2,
            (
                f"rendersim: compiling the native module with cargo ({shared}): on 2 cores about 1.5 minutes "
                "after `cargo build --release`, 2 on a fresh checkout (maturin's warning that the "
                "build backend is not maturin can be ignored: this one calls it)\n"
            ).encode(),
        )
    try:
        yield
    finally:
        if saved_fd is not None:
            os.write(2, f"rendersim: native module built in {time.monotonic() - started:.0f} s\n".encode())
            os.dup2(saved_fd, 2)
            os.close(saved_fd)
        if tty is not None:
            os.close(tty)
        if target is not None:
            os.environ.pop("CARGO_TARGET_DIR", None)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):  # noqa: D103
    with _checkout_habits():
        return maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


if hasattr(maturin, "build_editable"):

    def build_editable(wheel_directory, config_settings=None, metadata_directory=None):  # noqa: D103
        with _checkout_habits():
            return maturin.build_editable(wheel_directory, config_settings, metadata_directory)

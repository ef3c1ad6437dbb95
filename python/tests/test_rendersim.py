"""The Python package against the library and the command line: results,
determinism, errors (the CLI's message, file, line, key), the GIL released
while simulating. Run by scripts/test-all.sh (pytest); every file it writes
goes into pytest's temporary folders."""

import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rendersim

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
CAPTURE = ROOT / "tests" / "fixtures" / "presentmon" / "test_case_0.csv"


def cli():
    """The rendersim binary built beside the package, if any."""
    b = os.environ.get("RENDERSIM_BIN") or str(ROOT / "target" / "release" / "rendersim")
    return b if Path(b).is_file() else None


def test_run_of_the_default_model():
    r = rendersim.run(frames=90)
    assert r.summary["frames"] == 90
    assert r.summary["model"] == "<embedded default model>"
    ft = r.summary["metrics"]["frame_time_ms"]
    assert ft["count"] > 0 and ft["mean"] > 0
    assert isinstance(r.frames, pd.DataFrame)
    assert len(r.frames) == 90
    for col in ["Frame", "CPUStartTime", "MsUntilDisplayed", "MsGPUBusy", "Displayed", "Dropped"]:
        assert col in r.frames.columns
    assert r.frames["Frame"].tolist() == list(range(90))
    assert pd.api.types.is_float_dtype(r.frames["MsUntilDisplayed"])
    assert "[run]" in r.model or "run" in r.model
    p = r.summary["provenance"]
    assert p["program"] == f"rendersim {rendersim.__version__}"
    assert p["command"][1].startswith("rendersim.run(")


def test_same_seed_same_frames_and_the_model_text_reproduces_the_run(tmp_path):
    a = rendersim.run(MODELS / "fixed.toml", set={"workload.gpu": "9ms"}, seed=4, frames=50)
    b = rendersim.run(str(MODELS / "fixed.toml"), set={"workload.gpu": "9ms"}, seed=4, frames=50)
    pd.testing.assert_frame_equal(a.frames, b.frames)
    m = tmp_path / "model.toml"
    m.write_text(a.model)
    c = rendersim.run(m)
    pd.testing.assert_frame_equal(a.frames, c.frames)
    # save() writes the files `rendersim run --out` writes, byte for byte
    # (frames.csv and model.toml's body; the provenance differs by design).
    saved = a.save(tmp_path / "saved")
    exe = cli()
    if exe is not None:
        out = tmp_path / "cli"
        subprocess.run([exe, "run", str(MODELS / "fixed.toml"), "--set", "workload.gpu=9ms", "--seed", "4",
                        "--frames", "50", "--out", str(out)], check=True, capture_output=True)
        assert (saved / "frames.csv").read_bytes() == (out / "frames.csv").read_bytes()
        body = lambda p: [l for l in p.read_text().splitlines() if not l.startswith(("# Written by", "# Command:"))]
        assert body(saved / "model.toml") == body(out / "model.toml")
        # The saved folder is a run's result set: the command line writes
        # there again, and save() over the command line's folder too.
        ours = (saved / "frames.csv").read_bytes()
        subprocess.run([exe, "run", str(MODELS / "fixed.toml"), "--frames", "5", "--out", str(saved)],
                       check=True, capture_output=True)
        assert (saved / "frames.csv").read_bytes() != ours
        a.save(out)
        assert (out / "frames.csv").read_bytes() == ours
    assert a.save(saved) == saved and (saved / ".rendersim-set").is_file()
    # A folder holding someone else's files is refused, and left as it was.
    other = tmp_path / "mine"
    other.mkdir()
    (other / "notes.txt").write_text("keep me")
    with pytest.raises(rendersim.ModelError, match="notes.txt|not.*rendersim|refus"):
        a.save(other)
    assert (other / "notes.txt").read_text() == "keep me" and not (other / "frames.csv").exists()
    assert a.summary["metrics"]["gpu_time_ms"]["mean"] == pytest.approx(9.0)


def test_set_values_take_python_types():
    r = rendersim.run(
        MODELS / "fixed.toml",
        set={"display.buffers": 3, "display.vsync": False, "workload.gpu": "12ms", "display.refresh": "120Hz"},
        frames=40,
    )
    assert r.summary["metrics"]["frame_time_ms"]["mean"] == pytest.approx(12.0, rel=1e-6)
    assert rendersim.to_toml({"a": [1, 2.5, "x"], "b": True}) == '{ "a" = [1, 2.5, "x"], "b" = true }'
    with pytest.raises(rendersim.ModelError):
        rendersim.to_toml(object())


def test_errors_carry_file_line_key_and_the_cli_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[run]\nframes = 10\n[display]\nbufers = 3\n")
    with pytest.raises(rendersim.ModelError) as e:
        rendersim.run(bad)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.file == str(bad)
    assert err.line == 4
    assert err.key == "display.bufers"
    assert "did you mean" in str(err)
    exe = cli()
    if exe is not None:
        o = subprocess.run([exe, "run", str(bad)], capture_output=True, text=True)
        assert o.returncode == 2
        assert o.stderr.strip() == f"error: {err}"
    with pytest.raises(rendersim.ModelError) as e:
        rendersim.run(set={"display.buffers": -1}, frames=5)
    assert e.value.key == "display.buffers"
    # A value given as an argument is named as the argument, not as a file
    # or a command-line flag.
    with pytest.raises(rendersim.ModelError) as e:
        rendersim.run(set={"display.bufers": 3}, frames=5)
    assert (e.value.key, e.value.file, e.value.line) == ("display.bufers", None, None)
    assert str(e.value).startswith('set["display.bufers"] = 3 (applied to'), str(e.value)
    assert "--set" not in str(e.value) and "did you mean `buffers`" in str(e.value)
    with pytest.raises(rendersim.ModelError) as e:
        rendersim.run(set={"display": ["144Hz"]}, frames=5)
    assert "--set" not in str(e.value) and 'set["display"]' in str(e.value), str(e.value)
    # A file that does not exist is Python's own error.
    with pytest.raises(FileNotFoundError) as e:
        rendersim.run(tmp_path / "missing.toml")
    assert e.value.filename == str(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError):
        rendersim.replay(tmp_path / "missing.csv")
    with pytest.raises(rendersim.ModelError):
        rendersim.run(frames=-1)
    with pytest.raises(rendersim.ModelError):
        rendersim.vcache("grid:4x4", "fifo:zero")


def test_experiment_writes_its_folder_and_returns_dataframes(tmp_path):
    exp = tmp_path / "e.toml"
    exp.write_text(
        f'name = "py"\nmodel = "{MODELS / "fixed.toml"}"\nreplications = 2\n'
        '[set]\n"run.frames" = 80\n'
        '[[sweep]]\nkey = "workload.gpu"\nvalues = ["5ms", "20ms"]\n'
        '[[metric]]\npath = "metrics.frame_time_ms.mean"\n'
        '[[plot]]\nkind = "line"\nx = "workload.gpu"\ny = "metrics.frame_time_ms.mean"\nfile = "ft"\n'
    )
    out = tmp_path / "out"
    r = rendersim.experiment(exp, set={"display.buffers": 3}, out=out)
    assert r.out == out and (out / "report.md").is_file()
    assert len(r.points) == 2 and len(r.runs) == 4
    assert r.checks_failed == 0
    assert r.plots and all(p.is_file() for p in r.plots)
    assert "## Provenance" in r.report
    # Swept durations as numbers in ms, the unit in the name and attrs.
    assert list(r.points["workload.gpu_ms"]) == [5.0, 20.0]
    assert list(r.runs["workload.gpu_ms"]) == [5.0, 5.0, 20.0, 20.0]
    assert r.points.attrs["units"] == {"workload.gpu_ms": "ms"}
    assert r.points.attrs["swept"] == ["workload.gpu_ms"]
    # The points in tidy form: one row per point, metric and statistic,
    # each value the wide table's.
    long = r.points_long
    assert list(long.columns) == ["point", "workload.gpu_ms", "metric", "stat", "value"]
    stats = [c for c in r.points.columns if ":" in c]
    assert len(long) == len(r.points) * len(stats)
    mean = long[(long.metric == "metrics.frame_time_ms.mean") & (long.stat == "mean")]
    assert list(mean.value) == list(r.points["metrics.frame_time_ms.mean:mean"])
    assert long.attrs["units"] == {"workload.gpu_ms": "ms"}


def test_typed_sweeps_convert_units_and_leave_other_values():
    from rendersim import _typed_sweeps

    df = pd.DataFrame(
        {
            "point": [0, 1, 2],
            "workload.gpu": ["500us", "2ms", "0"],
            "display.refresh": ["60Hz", "1kHz", "144Hz"],
            "model": ["a.toml", "b.toml", "c.toml"],
            "mixed": ["60Hz", "16ms", "1s"],
            "display.buffers": [2, 3, 4],
            "m:mean": [1.0, 2.0, 3.0],
        }
    )
    out = _typed_sweeps(df, ["workload.gpu", "display.refresh", "model", "mixed", "display.buffers"])
    assert list(out["workload.gpu_ms"]) == [0.5, 2.0, 0.0]
    assert list(out["display.refresh_hz"]) == [60.0, 1000.0, 144.0]
    assert list(out["model"]) == ["a.toml", "b.toml", "c.toml"]
    assert list(out["mixed"]) == ["60Hz", "16ms", "1s"]
    assert list(out["display.buffers"]) == [2, 3, 4]
    assert out.attrs["units"] == {"workload.gpu_ms": "ms", "display.refresh_hz": "Hz"}
    assert out.attrs["swept"] == ["workload.gpu_ms", "display.refresh_hz", "model", "mixed", "display.buffers"]


def test_experiment_progress_reports_every_run_and_a_raise_stops_it(tmp_path):
    exp = tmp_path / "e.toml"
    exp.write_text(
        f'name = "py"\nmodel = "{MODELS / "fixed.toml"}"\nreplications = 3\n'
        '[set]\n"run.frames" = 80\n'
        '[[sweep]]\nkey = "workload.gpu"\nvalues = ["5ms", "10ms", "20ms"]\n'
        '[[metric]]\npath = "metrics.frame_time_ms.mean"\n'
    )
    seen = []
    lock = threading.Lock()

    def note(done, total):
        with lock:
            seen.append((done, total))

    rendersim.experiment(exp, out=tmp_path / "a", progress=note)
    assert sorted(seen) == [(d, 9) for d in range(1, 10)]

    class Enough(Exception):
        pass

    def stop(done, total):
        raise Enough(f"{done} of {total}")

    with pytest.raises(Enough):
        rendersim.experiment(exp, out=tmp_path / "b", progress=stop)
    assert not (tmp_path / "b").exists(), "a stopped experiment leaves no folder"
    with pytest.raises(TypeError):
        rendersim.experiment(exp, out=tmp_path / "c", progress="yes")


def test_vcache_isolate_and_replay():
    v = rendersim.vcache("grid:16x16", "fifo:32")
    assert v["triangles"] == 512 and v["unique_vertices"] == 289
    assert 0 < v["acmr"] <= 3
    iso = rendersim.isolate(MODELS / "fixed.toml")
    assert iso["bottleneck"] == "gpu"
    rp = rendersim.replay(CAPTURE)
    assert rp.summary["frames"] > 100
    assert rp.summary["agreement"]["displayed"] >= 0.99
    assert len(rp.comparison) == rp.summary["frames"]
    assert rp.whatif_frames is None
    assert rp.comparison["Line"].dtype == "int64" and rp.comparison["Displayed"].dtype == bool
    assert rp.comparison["MsUntilDisplayed"].dtype == float
    w = rendersim.replay(CAPTURE, set={"display.refresh": "120Hz"})
    assert w.whatif_frames is not None and len(w.whatif_frames) > 0


def test_replay_tables_equal_the_command_line_files(tmp_path):
    """The replay's DataFrames, built from its numbers, hold what the
    command line's CSV files hold, read back."""
    from rendersim import _csv

    exe = cli()
    if exe is None:
        pytest.skip("no rendersim binary (cargo build --release)")
    out = tmp_path / "r"
    subprocess.run(
        [exe, "replay", str(CAPTURE), "--set", "display.refresh=120Hz", "--out", str(out)],
        check=True,
        capture_output=True,
    )
    w = rendersim.replay(CAPTURE, set={"display.refresh": "120Hz"})
    pd.testing.assert_frame_equal(w.frames, _csv((out / "frames.csv").read_text()))
    pd.testing.assert_frame_equal(w.whatif_frames, _csv((out / "whatif-frames.csv").read_text()))
    measured = pd.read_csv(out / "comparison.csv")
    assert list(measured.columns) == list(w.comparison.columns)
    for c in measured.columns:
        np.testing.assert_array_equal(measured[c].to_numpy(dtype=float), w.comparison[c].to_numpy(dtype=float))


def test_the_gil_is_released_while_simulating():
    """A Python thread keeps counting while another simulates."""
    done = threading.Event()
    count = [0]

    def spin():
        while not done.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        start = time.perf_counter()
        before = count[0]
        rendersim.run(frames=120)
        during = count[0] - before
        elapsed = time.perf_counter() - start
    finally:
        done.set()
        t.join()
    # Holding the GIL for the whole run would leave the counter at (almost)
    # nothing; released, it counts throughout.
    assert elapsed > 0.05
    assert during > 10_000, f"{during} increments in {elapsed:.2f} s"


def test_cli_style_sets_timeline_and_perceived_speed(tmp_path):
    a = rendersim.run(MODELS / "fixed.toml", sets=["workload.gpu=12ms", "display.buffers=3"], frames=40)
    b = rendersim.run(MODELS / "fixed.toml", set={"workload.gpu": "12ms", "display.buffers": 3}, frames=40)
    pd.testing.assert_frame_equal(a.frames, b.frames)
    with pytest.raises(rendersim.ModelError):
        rendersim.run(sets="display.buffers=3")
    t = rendersim.timeline(tmp_path / "t.png", MODELS / "fixed.toml", frames=4, first=2)
    assert t["frames"] == (2, 5) and t["range_ms"][1] > t["range_ms"][0]
    assert (tmp_path / "t.png").stat().st_size > 1000
    with pytest.raises(rendersim.ModelError) as e:
        rendersim.timeline(tmp_path / "t.png", frames=0)
    assert "frames" in str(e.value)
    with pytest.raises(rendersim.ModelError):
        rendersim.timeline(tmp_path / "t.gif", frames=2)
    p = rendersim.perceived_speed(
        MODELS / "walkthrough-forest.toml",
        tmp_path / "f6.png",
        sets=["run.frames=120"],
    )
    assert p["refreshes"][1] >= p["refreshes"][0]
    assert (tmp_path / "f6.png").is_file() and (tmp_path / "f6.svg").is_file()


def test_the_errors_are_a_small_hierarchy():
    """ModelError and SimulationError are rendersim.Error; a run that fails
    while running is a SimulationError, also a RuntimeError."""
    from rendersim.errors import from_native

    assert issubclass(rendersim.ModelError, (rendersim.Error, ValueError))
    assert issubclass(rendersim.SimulationError, (rendersim.ModelError, RuntimeError))

    class Native(Exception):
        pass

    n = Native("m.toml: the run stopped at 1 s before frame 3 (cpu idle)")
    n.kind, n.file, n.line, n.key = "simulation", None, None, None
    e = from_native(n)
    assert isinstance(e, rendersim.SimulationError) and isinstance(e, RuntimeError)
    n = Native('--set "run.frames=abc": run.frames must be a whole number >= 0')
    n.kind, n.file, n.line, n.key = "model", None, None, "run.frames"
    e = from_native(n)
    assert type(e) is rendersim.ModelError
    assert str(e) == 'set["run.frames"] = abc: run.frames must be a whole number >= 0'


def test_a_model_is_a_path_toml_text_a_dict_or_a_model(tmp_path):
    """Issue 58 item 1: every form of a model gives the same run."""
    fixed = MODELS / "fixed.toml"
    by_path = rendersim.run(fixed, frames=30)
    m = rendersim.Model.load(fixed)
    assert m.system == "frame_pipeline" and m.name == str(fixed)
    assert repr(m) == f"<rendersim.Model frame_pipeline from {fixed}>"
    by_model = rendersim.run(m, frames=30)
    by_text = rendersim.run(fixed.read_text(), frames=30)
    by_dict = rendersim.run(m.to_dict(), frames=30)
    by_back = rendersim.run(by_path.model, frames=30)  # a run's resolved model, passed back
    for r in (by_model, by_text, by_dict, by_back):
        pd.testing.assert_frame_equal(r.frames, by_path.frames)
    # Changes: checked at once, kept in order, shown in the repr, and the
    # same as set= on the call.
    m3 = m.set("display.buffers", 3).set("workload.gpu", "12ms")
    assert m3.changes == {"display.buffers": 3, "workload.gpu": "12ms"} and m.changes == {}
    assert repr(m3).endswith("changed: display.buffers=3, workload.gpu='12ms'>")
    assert m3.to_dict()["display"]["buffers"] == 3
    assert "buffers = 3" in m3.to_toml()
    a = rendersim.run(m3, frames=30)
    b = rendersim.run(fixed, set={"display.buffers": 3, "workload.gpu": "12ms"}, frames=30)
    pd.testing.assert_frame_equal(a.frames, b.frames)
    assert rendersim.Model.from_toml(m3.to_toml()) == m3
    with pytest.raises(rendersim.ModelError) as e:
        m.set("display.bufers", 3)
    assert e.value.key == "display.bufers" and "--set" not in str(e.value)
    # A dict model, and the embedded default as Model().
    d = rendersim.run({"workload": {"kind": "fixed", "cpu": "2ms", "gpu": "5ms"}, "run": {"frames": 20}})
    assert d.summary["frames"] == 20
    assert rendersim.Model().system == "frame_pipeline"
    assert rendersim.isolate(m3)["bottleneck"] == "gpu"
    with pytest.raises(FileNotFoundError):
        rendersim.Model.load(tmp_path / "missing.toml")
    with pytest.raises(TypeError) as e:
        rendersim.run(42)
    assert "a path, TOML text, a dict or a rendersim.Model" in str(e.value)


def test_the_docstring_examples_run(monkeypatch):
    """The examples in rendersim.model's and rendersim.errors' docstrings."""
    import doctest

    import rendersim.errors
    import rendersim.model

    monkeypatch.chdir(MODELS.parent)
    for module in (rendersim.model, rendersim.errors):
        failed, tried = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert tried > 0 and failed == 0, module.__name__


@pytest.mark.parametrize(
    "model,changes",
    [
        ("fixed.toml", {}),
        ("fixed.toml", {"frame_generation.enabled": True}),
        ("fixed.toml", {"display.vsync": False, "display.present_mode": "immediate"}),
        ("walkthrough-city.toml", {}),
    ],
)
def test_frames_reach_pandas_without_text_and_equal_the_csv(model, changes):
    """Issue 58 item 1: Run.frames is built from the numbers the native
    module holds, no CSV in between; it equals frames.csv as read back,
    value for value and type for type (Displayed and Dropped booleans),
    with generated frames, NA cells and another system's table."""
    from rendersim import _csv

    r = rendersim.run(MODELS / model, set=changes, frames=80)
    pd.testing.assert_frame_equal(r.frames, _csv(r.frames_csv))
    if "Displayed" in r.frames:
        assert r.frames["Displayed"].dtype == bool and r.frames["Dropped"].dtype == bool


def test_progress_reporters(capsys, monkeypatch):
    """``rendersim.progress``: its examples, the terminal line, the
    notebook bar (over stand-in widgets) and what it refuses."""
    import doctest
    import sys
    import types

    from rendersim import progress

    assert doctest.testmod(progress).failed == 0
    line = progress.reporter(True)
    line(1, 4)
    line(4, 4)
    err = capsys.readouterr().err
    assert "\r[#######" in err and "1/4 runs" in err
    assert err.rstrip("\n").rsplit("\r", 1)[1].startswith("[" + "#" * 30 + "] 4/4 runs") and err.endswith("\n")
    # Not a terminal: nothing unless asked.
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    assert progress.reporter(None) is None

    class Widget:
        def __init__(self, *args, **kw):
            self.__dict__.update(kw)
            self.value = kw.get("value", args[0] if args else None)

    shown = []
    widgets = types.SimpleNamespace(IntProgress=Widget, Label=Widget, HBox=Widget)
    bar = progress._NotebookBar(widgets, shown.append)
    bar(3, 10)
    assert (bar.bar.value, bar.bar.max) == (3, 10) and bar.label.value.startswith("3/10 runs")
    bar(10, 10)
    assert bar.bar.bar_style == "success" and len(shown) == 1
    with pytest.raises(TypeError):
        progress.reporter("yes")

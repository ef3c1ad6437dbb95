"""A new user's first Python session (issue 58's target), step by step as
the README shows it: the README's example, a dict model, a typo in a key,
a missing file, a 200,000-frame run into pandas, an experiment into a tidy
DataFrame, a run saved. Each step either works or raises the error a Python user
expects, with a message in Python's terms."""

import os
from pathlib import Path

import pandas as pd
import pytest

import rendersim

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def in_the_checkout(monkeypatch):
    # The README's paths are the checkout's.
    monkeypatch.chdir(ROOT)


def test_the_readme_example():
    r = rendersim.run(set={"display.buffers": 3}, seed=1, frames=300)
    assert r.summary["metrics"]["display_latency_ms"]["mean"] > 0
    assert isinstance(r.frames, pd.DataFrame) and len(r.frames) > 0
    assert "[display]" in r.model
    m = rendersim.Model.load("models/fixed.toml").set("display.buffers", 3)
    assert repr(m) == "<rendersim.Model frame_pipeline from models/fixed.toml, changed: display.buffers=3>"
    assert rendersim.run(m, frames=300).summary["frames"] == 300
    assert rendersim.vcache("grid:64x64", "fifo:32")["acmr"] > 0
    assert rendersim.isolate("models/fixed.toml")["bottleneck"]
    w = rendersim.replay("tests/fixtures/presentmon/test_case_0.csv", set={"display.refresh": "120Hz"})
    assert w.whatif_frames is not None


def test_a_dict_model():
    model = {
        "display": {"refresh": "60Hz", "vsync": True, "buffers": 2},
        "workload": {"kind": "fixed", "cpu": "4ms", "gpu": "10ms"},
        "noise": {"enabled": False},
    }
    r = rendersim.run(model, frames=60)
    # The GPU (10 ms) fits a refresh: frames at 60 Hz once the pipeline fills.
    assert r.summary["metrics"]["frame_time_ms"]["p50"] == pytest.approx(1000 / 60, rel=1e-6)
    # And back: the run's model runs again as text.
    again = rendersim.run(r.model, frames=60)
    pd.testing.assert_frame_equal(again.frames, r.frames)


def test_a_typo_in_a_key():
    with pytest.raises(ValueError) as e:  # a ModelError is a ValueError
        rendersim.run(set={"display.bufers": 3})
    err = e.value
    assert isinstance(err, rendersim.ModelError)
    assert err.key == "display.bufers" and err.file is None
    assert str(err).startswith('set["display.bufers"] = 3')
    assert "did you mean `buffers`" in str(err) and "--set" not in str(err)


def test_a_missing_file():
    with pytest.raises(FileNotFoundError) as e:
        rendersim.run("models/no-such-model.toml")
    assert e.value.filename == "models/no-such-model.toml"
    assert not isinstance(e.value, rendersim.Error)


def test_200000_frames_into_pandas():
    r = rendersim.run("models/fixed.toml", frames=200_000)
    f = r.frames
    assert len(f) == 200_000
    assert f["Displayed"].dtype == bool and f["MsUntilDisplayed"].dtype == float
    assert f.loc[f.Displayed, "MsUntilDisplayed"].notna().all()


def test_an_experiment_into_a_tidy_dataframe(tmp_path):
    e = rendersim.experiment("experiments/vsync-quantization.toml", out=tmp_path / "vq")
    assert e.checks_failed == 0
    long = e.points_long
    assert list(long.columns) == ["point", "workload.gpu_ms", "display.buffers", "metric", "stat", "value"]
    # Swept durations are numbers: a plot's x axis or a filter as is.
    fast = long[(long["workload.gpu_ms"] < 16) & (long.stat == "mean")]
    assert len(fast) > 0
    table = long[long.stat == "mean"].pivot_table(index="point", columns="metric", values="value")
    assert len(table) == len(e.points)
    assert os.path.isfile(e.out / "report.md")


def test_saving_a_run_where_the_command_line_writes(tmp_path):
    r = rendersim.run(frames=50)
    out = r.save(tmp_path / "run")
    assert sorted(p.name for p in out.iterdir()) == [".rendersim-set", "frames.csv", "model.toml", "summary.json"]
    assert r.save(out) == out  # its own folder: replaced whole

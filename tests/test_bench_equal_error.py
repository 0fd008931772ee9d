# SPDX-License-Identifier: GPL-2.0-or-later
"""bench/run_benchmark.py's equal_error: the report's "Cycles at equal
error" cells from the Cycles series already rendered and the renders in its
cache. Each count that the search asks for between two powers of 2 is read
from the render cache (the .npz and .json that render_jobs.py writes), as a
second run of the benchmark reads it; these tests fill that cache
themselves, so no Blender runs (a count missing from it would start one,
which the environment here cannot: the test would fail). metrics.py's
reading itself is test_bench_metrics.py's. Plain pytest."""
import json
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from conftest import REPO

sys.path.insert(0, str(REPO / "bench"))
import metrics  # noqa: E402
import run_benchmark  # noqa: E402

# The image: 40 x 30, every pixel compared but the left column (the mask).
WIDTH, HEIGHT = 40, 30
TRUTH = np.linspace(0.2, 0.9, WIDTH * HEIGHT, dtype=np.float32).reshape(HEIGHT, WIDTH)
MASK = np.ones((HEIGHT, WIDTH), bool)
MASK[:, 0] = False
# Cycles' RMSE at each count: powers of 2 do better than the counts after them.
RMSE = {1: 0.4, 2: 0.25, 3: 0.19, 4: 0.15, 8: 0.09, 9: 0.095, 10: 0.085, 11: 0.07, 12: 0.066,
        13: 0.064, 16: 0.05}
# A render's time: 0.2 s to start and 0.01 s a sample for the series; the
# counts between its powers of 2 take 0.05 s more (another Blender's start),
# so that Cycles' fitted time shows which renders it was fitted to.
SECONDS = {n: 0.2 + 0.01 * n + (0.0 if n in (1, 2, 4, 8, 16) else 0.05) for n in RMSE}
MODE = SimpleNamespace(width=WIDTH, height=HEIGHT, cycles_series=(1, 2, 4, 8, 16),
                       cycles_repeats=3, cycles_repeat_below=8)
DATA = SimpleNamespace(scene="interior", truth=TRUTH, mask=MASK)


def render_with_rmse(rmse):
    """AO whose RMSE against TRUTH over MASK is `rmse`: TRUTH +- rmse, in a
    checkerboard, and the masked-out column far off (it must not count)."""
    signs = np.where((np.indices(TRUTH.shape).sum(axis=0) % 2) == 0, 1.0, -1.0)
    ao = TRUTH.astype(np.float64) + rmse * signs
    ao[:, 0] = 5.0
    return ao


def fill_cache(cache, counts):
    """Writes the cycles_job renders of `counts` into the cache, as render_jobs.py does."""
    cache.mkdir(parents=True, exist_ok=True)
    for samples in counts:
        job = run_benchmark.cycles_job(MODE, samples, MODE.cycles_repeats)
        np.savez(cache / f"{job['id']}.npz", ao=render_with_rmse(RMSE[samples]))
        (cache / f"{job['id']}.json").write_text(json.dumps({"time_s": SECONDS[samples]}))


def result_of(sweep_rmse):
    """The scene's result as run_benchmark has it when equal_error runs: the
    Cycles series (with its times and errors) and the sweep's entries."""
    return {"cycles": [{"samples": n, "seconds": SECONDS[n], "rmse": RMSE[n]}
                       for n in MODE.cycles_series],
            "sweep": [{"key": key, "rmse": rmse} for key, rmse in sweep_rmse.items()]}


@pytest.fixture()
def no_blender(monkeypatch, tmp_path):
    """The environment for renders, in which a render cannot run: BLENDER
    names no program, so a count missing from the cache raises."""
    monkeypatch.setattr(run_benchmark, "BLENDER", str(tmp_path / "no-blender-here"))
    return {}


def test_the_cached_renders_have_the_rmse_they_stand_for():
    for rmse in (0.05, 0.19):
        stats = metrics.error_stats(render_with_rmse(rmse), TRUTH, MASK)
        assert stats["rmse"] == pytest.approx(rmse, rel=1e-9)


def test_each_key_gets_the_least_whole_count_and_cycles_time_there(tmp_path, no_blender):
    cache = tmp_path / "renders"
    # 0.068: 8 misses it, 16 reaches it; of 9, 10, 11 and 12, 12 is the first
    # to (13 is never asked). 0.2: 2 misses, 4 reaches, 3 is the first. 0.5:
    # one sample reaches it.
    fill_cache(cache, (3, 9, 10, 11, 12, 13))
    result = result_of({"fast": 0.068, "coarse": 0.2, "first": 0.5, "unused": 0.3})
    found = run_benchmark.equal_error(DATA, result, {"fast", "coarse", "first"}, MODE, cache,
                                      no_blender, tmp_path / "bunny.json")
    assert set(found) == {"fast", "coarse", "first"}
    made = (1, 2, 4, 8, 16, 3, 9, 10, 11, 12)  # the series and what the search rendered
    times = sorted((n, SECONDS[n]) for n in made)
    for key, whole, rmse in (("fast", 12, 0.068), ("coarse", 3, 0.2)):
        entry = found[key]
        assert entry["whole"] == whole
        assert entry["whole_rmse"] == pytest.approx(RMSE[whole], rel=1e-9)
        assert whole - 1 < entry["samples"] <= whole
        assert entry["samples"] == pytest.approx(
            metrics.samples_for_rmse([(whole - 1, RMSE[whole - 1]), (whole, RMSE[whole])],
                                     rmse), rel=1e-9)
        # Cycles' time at the count, on the line through every render made
        # (13 was not asked for, so its render is not among them)
        assert entry["seconds"] == pytest.approx(
            metrics.cycles_seconds_at(times, entry["samples"]), rel=1e-9)
        series_only = metrics.cycles_seconds_at(
            [(n, SECONDS[n]) for n in MODE.cycles_series], entry["samples"])
        assert entry["seconds"] != pytest.approx(series_only, rel=1e-3)
    assert found["first"]["whole"] == 1 and found["first"]["samples"] == 1.0
    assert found["first"]["seconds"] == pytest.approx(metrics.cycles_seconds_at(times, 1.0))


def test_a_key_beyond_the_series_most_samples_has_no_count(tmp_path, no_blender, capsys):
    cache = tmp_path / "renders"
    result = result_of({"fine": 0.01})
    found = run_benchmark.equal_error(DATA, result, {"fine"}, MODE, cache, no_blender,
                                      tmp_path / "bunny.json")
    assert found == {"fine": None}  # the report says "more than 16"
    said = capsys.readouterr().out
    assert "interior fine: Cycles at 16 samples does not reach RMSE 0.0100" in said


def test_a_count_missing_from_the_cache_is_rendered(tmp_path, no_blender):
    """The search renders what the cache lacks: here, where no Blender
    runs, that fails (and so would the tests above, had they asked for a
    count they did not cache)."""
    cache = tmp_path / "renders"
    fill_cache(cache, (9, 10, 11))  # 12 missing
    with pytest.raises(FileNotFoundError, match="no-blender-here"):
        run_benchmark.equal_error(DATA, result_of({"fast": 0.068}), {"fast"}, MODE, cache,
                                  no_blender, tmp_path / "bunny.json")

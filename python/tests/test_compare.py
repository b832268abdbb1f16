"""ais.compare: the study from Python returns its tables as dicts and writes the report."""

from __future__ import annotations

import math

import pytest

import ais


def test_compare_returns_tables_and_writes_the_report(cornell, tmp_path):
    result = ais.compare(
        cornell,
        output=tmp_path / "report",
        resolution=(32, 32),
        time_budget=0.1,
        seeds=2,
        reference_spp=256,
        configs=["off", "aggressive"],
        rays=8,
    )
    names = [c["name"] for c in result["configurations"]]
    assert names == ["mis-off", "mis-aggressive", "mis-oracle"]
    baseline, aggressive, oracle = result["configurations"]
    assert baseline["equal_time"]["ratio"] == pytest.approx(1.0)
    assert baseline["equal_rays"]["ratio"] == pytest.approx(1.0)
    assert baseline["equal_time"]["mse_ratio"] == pytest.approx(1.0)
    assert baseline["equal_rays"]["mse_ratio"] == pytest.approx(1.0)
    assert baseline["equal_time"]["relative_alike_ratio"] == pytest.approx(1.0)
    assert oracle["oracle"] and oracle["equal_time"] is None
    assert oracle["equal_rays"]["oracle_share"] == pytest.approx(1.0)
    for row in (baseline, aggressive):
        time = row["equal_time"]
        assert time["spp"] >= 1 and time["rel_mse"]["mean"] > 0
        assert math.isfinite(time["rel_mse"]["error"])
        # Every pixel weighted alike, against relMSE's 1 / (r² + 0.01) ≤ 100.
        assert 0 < time["mse"]["mean"] and math.isfinite(time["mse"]["error"])
        assert 0 < time["relative_alike"]["mean"]
        assert time["nominal_rays_per_pixel"] == pytest.approx(time["spp"] * 8)
    assert aggressive["equal_time"]["rejected_per_pixel"] > 0
    assert "| mis-aggressive |" in result["tables"]
    assert result["report"].endswith("index.html")
    assert (tmp_path / "report" / "index.html").stat().st_size > 10_000
    assert result["ray_budget"] > 0


def test_compare_refuses_bad_requests(cornell, tmp_path):
    with pytest.raises(ValueError, match="time budget"):
        ais.compare(cornell, output=tmp_path, time_budget=0.0)
    with pytest.raises(ValueError, match="neither an AIS preset"):
        ais.compare(cornell, output=tmp_path, configs=["sometimes"], time_budget=0.1)
    with pytest.raises(TypeError, match="unexpected keyword argument 'budget_s'"):
        ais.compare(cornell, budget_s=2)

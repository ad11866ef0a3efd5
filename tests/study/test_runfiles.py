"""plough.study.runfiles.figure_view: the part of the config a figure's dataset reads."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from plough.study import matrix, runfiles

ROOT = Path(__file__).resolve().parents[2]
FULL = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.mark.parametrize("figure", ["fig13", "fig21"])
def test_a_sweep_figures_view_lists_its_gated_runs_finding_them_once(monkeypatch, figure):
    """The workflow evaluates the view of every MPM figure while it builds the DAG: finding the gated
    (skippable, failure-recordable) runs, which places every sweep point on its ladder with the analytical
    model, is done once per view, not once per run of the figure (a dry run of the full matrix spent 66 s
    there)."""
    calls = []
    original = matrix.finest_sweep_runs

    def counted(config):
        calls.append(1)
        return original(config)

    monkeypatch.setattr(matrix, "finest_sweep_runs", counted)
    view = runfiles.figure_view(FULL, figure)
    runs = matrix.figure_runs(FULL, figure)
    assert len(runs) > 10
    assert len(calls) == 2  # skippable_runs and failure_recordable_runs, each once
    gated = original(FULL)
    assert view["skippable"] == [r for r in runs if r in gated]
    assert view["recordable"] == [r for r in runs if r in gated]
    assert view["skippable"]  # the full matrix gates some of this figure's finest runs

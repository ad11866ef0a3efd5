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
    model, is done once per view, for both roles, not once per run of the figure (a dry run of the full matrix
    spent 66 s there)."""
    calls = []
    original = matrix.finest_sweep_runs

    def counted(config):
        calls.append(1)
        return original(config)

    monkeypatch.setattr(matrix, "finest_sweep_runs", counted)
    view = runfiles.figure_view(FULL, figure)
    runs = matrix.figure_runs(FULL, figure)
    assert len(runs) > 10
    assert len(calls) == 1  # both roles from one search (matrix.finest_run_roles)
    finest = original(FULL)
    gated = set(finest) - matrix._finest_runs_set_by(FULL, matrix.UNGATED_TARGETS)
    assert view["skippable"] == [r for r in runs if r in gated]
    assert view["recordable"] == [r for r in runs if r in finest]
    assert view["skippable"]  # the full matrix gates some of this figure's finest runs
    assert set(view["recordable"]) - set(view["skippable"])  # and leaves a groove- or coating-set one ungated


@pytest.mark.parametrize(("tolerance", "failure", "skippable", "recordable"),
                         [(None, "record", False, True), ({"mu": 0.05, "dp": 0.3}, "stop", True, False),
                          (None, "stop", False, False)])
def test_each_finest_role_follows_its_own_option(tolerance, failure, skippable, recordable):
    config = {**FULL, "mpm": {**FULL["mpm"], "skip_finest_tolerance": tolerance, "finest_failure": failure}}
    finest = matrix.finest_sweep_runs(config)
    ungated = matrix._finest_runs_set_by(config, matrix.UNGATED_TARGETS)
    gated = {rid: pair for rid, pair in finest.items() if rid not in ungated}
    assert gated and ungated and ungated <= set(finest)
    s, r = matrix.finest_run_roles(config)
    assert s == (gated if skippable else {})
    assert r == (finest if recordable else {})
    assert (matrix.skippable_runs(config), matrix.failure_recordable_runs(config)) == (s, r)


def test_a_wrong_finest_failure_is_refused_by_name():
    config = {**FULL, "mpm": {**FULL["mpm"], "finest_failure": "ignore"}}
    with pytest.raises(ValueError, match="mpm.finest_failure = 'ignore' is unknown; allowed: record, stop"):
        matrix.finest_run_roles(config)

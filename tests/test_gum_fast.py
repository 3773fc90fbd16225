"""The GUM's fast paths give the plain computation's numbers.

- the finite differences: the sparse kernel gives, bit for bit, what evaluating every perturbed vector gives
  (the differences amplify the means' last bits, so nothing less would do);
- the prediction's figures (:func:`plansim.uncertainty.gum.gum_uncertainties`) are those of the budgets
  (:func:`plansim.uncertainty.gum.evaluate_gum`), to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest

from plansim.io.scenario_file import load_scenario
from plansim.kernels.layout import HEAD, PER_SEGMENT, SEG_PHASE, draws_length, segment_base
from plansim.simulate.arguments import noise_free_segment_means
from plansim.uncertainty.gum import evaluate_gum, gum_uncertainties
from plansim.uncertainty.sensitivities import PHASE_NODES, phase_grid_draws, segment_mean_derivatives


def _dense(scenario, indices, steps):
    """Every perturbed draws vector at every start angle through the plain kernel, averaged with numpy."""
    grid = phase_grid_draws(scenario)
    n_in, n_seg = len(indices), len(scenario.schedule)
    plus = np.repeat(grid[None], n_in, axis=0)
    minus = plus.copy()
    k = np.arange(n_in)
    plus[k, :, indices] += steps[:, None]
    minus[k, :, indices] -= steps[:, None]
    shape = (n_in, PHASE_NODES, n_seg, 6)
    mean_plus = noise_free_segment_means(scenario, plus.reshape(-1, grid.shape[1])).reshape(shape).mean(1)
    mean_minus = noise_free_segment_means(scenario, minus.reshape(-1, grid.shape[1])).reshape(shape).mean(1)
    nominal = noise_free_segment_means(scenario, grid)
    centre = nominal.mean(axis=0)
    return (nominal, (mean_plus - mean_minus) / (2.0 * steps[:, None, None]),
            (mean_plus + mean_minus - 2.0 * centre[None]) / steps[:, None, None] ** 2)


@pytest.mark.parametrize("name, overrides", [("jjf2003", ()), ("coarse_quantisation", ("schedule.positions=6",))])
def test_sparse_differences_are_the_dense_ones_bit_for_bit(name, overrides):
    """Every head component (truth, fixture, tilt, rate error, perpendicularity) and every component of a static
    and of a rotating segment: the finite differences amplify the means' last bits, so they must be equal."""
    scenario = load_scenario(name, overrides)
    segments = scenario.schedule.segments
    picked = [next(s for s, seg in enumerate(segments) if seg.rate == 0.0),
              next(s for s, seg in enumerate(segments) if seg.rate != 0.0)]
    indices = np.array(list(range(HEAD)) + [segment_base(s) + k for s in picked for k in range(PER_SEGMENT)
                                            if k != SEG_PHASE])
    steps = np.exp(np.random.default_rng(0).normal(-10.0, 2.0, size=indices.size))
    for dense, sparse in zip(_dense(scenario, indices, steps), segment_mean_derivatives(scenario, indices, steps)):
        assert np.array_equal(dense, sparse)


def test_start_angles_are_refused():
    scenario = load_scenario("jjf2003")
    with pytest.raises(ValueError, match="start angles"):
        segment_mean_derivatives(scenario, np.array([segment_base(0) + SEG_PHASE]), np.array([1e-3]))
    with pytest.raises(ValueError, match="start angles"):
        segment_mean_derivatives(scenario, np.array([draws_length(len(scenario.schedule))]), np.array([1e-3]))


@pytest.mark.parametrize("name, overrides", [("jjf2003", ()), ("linear_gaussian", ("schedule.dwell=10 s",))])
def test_the_figures_are_those_of_the_budgets(name, overrides):
    """The same lines and arithmetic; the table lines' columns by one BLAS product instead of einsum
    (model_lines(describe=False)), so the same to rounding: 1e-15 (8e-16 seen)."""
    scenario = load_scenario(name, overrides)
    figures = gum_uncertainties(scenario, coverage_probability=0.9)
    gum = evaluate_gum(scenario, coverage_probability=0.9)
    u = gum.standard_uncertainty
    assert np.all(np.abs(figures.covariance - gum.covariance) <= 1e-15 * np.outer(u, u))
    assert np.allclose(figures.standard_uncertainty, u, rtol=1e-15, atol=0)
    assert np.array_equal(figures.estimate, gum.estimate)
    assert np.allclose(figures.effective_dof, [b.effective_dof for b in gum.budgets], rtol=2e-15, atol=0)
    assert np.allclose(figures.coverage_factor, [b.coverage_factor for b in gum.budgets], rtol=1e-15, atol=0)
    assert np.allclose(figures.expanded_uncertainty, gum.expanded_uncertainty, rtol=2e-15, atol=0)

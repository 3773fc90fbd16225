"""Figures: where a person would rather look than read."""

from __future__ import annotations

import os

import numpy as np

from plansim.io.files import atomic_write
from plansim.uncertainty.appendix_a import APPENDIX_A, errors_in_reading_units

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def appendix_a_histograms(results, scenario, comparisons, path: str | os.PathLike) -> None:
    """Histogram of |error| of each Appendix A quantity (in its reading, log axis) with the claimed U and the MC 95 % point."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    by_item = {c.item: c for c in comparisons}
    fig, axes = plt.subplots(1, len(APPENDIX_A), figsize=(3.4 * len(APPENDIX_A), 3.4), constrained_layout=True)
    for ax, budget in zip(np.atleast_1d(axes), APPENDIX_A):
        c = by_item[budget.item]
        pooled = np.abs(np.concatenate([
            errors_in_reading_units(budget, name, results["error"].sel(parameter=name).values, scenario,
                                    truth=results["truth"].sel(parameter=name).values)
            for name in budget.parameters]))
        # |error| on a log axis: the claimed U and the achieved spread can differ by orders of magnitude
        positive = pooled[pooled > 0]
        low = min(positive.min() if positive.size else c.budget_U * 1e-3, c.budget_U) / 2
        high = max(pooled.max(), c.budget_U) * 2
        ax.hist(pooled, bins=np.geomspace(low, high, 60), color="0.6")
        ax.set_xscale("log")
        ax.axvline(c.budget_U, color="tab:red", ls="--", label="claimed U (k = 2)")
        ax.axvline(c.mc_U95, color="tab:blue", ls=":", label="MC: 95 % of |error| below")
        short = budget.quantity.split(" (")[0]
        ax.set_title(f"{budget.item} {short}\n{c.coverage:.1%} of |error| ≤ U; {c.verdict}", fontsize=8)
        ax.set_xlabel(f"|error| in {c.reading_unit.split(' (')[0]}", fontsize=8)
        ax.tick_params(labelsize=7)
    np.atleast_1d(axes)[0].set_ylabel("trials × parameters")
    np.atleast_1d(axes)[0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"plansim: {results.attrs['scenario']} — {results.attrs['trials']} trials, seed "
                 f"{results.attrs['seed']}: JJF 2003 Appendix A claims vs Monte Carlo", fontsize=10)
    suffix = os.path.splitext(str(path))[1].lower()
    atomic_write(path, lambda tmp: fig.savefig(tmp, format=suffix[1:], dpi=120))
    plt.close(fig)

"""``plansim run chapter``'s report: the chapter's procedures against JJF 2003 on the same units
(:mod:`plansim.uncertainty.chapter_comparison`; docs/chapter-procedures.md).

The text table and the figure show each quantity in a laboratory's unit (misalignments and cross-axis terms in
ppm of the scale factor, D0 in °/h, D1–D3 in °/h/g); the JSON object keeps SI.
"""

from __future__ import annotations

import math
import os

import numpy as np

from plansim.report.plot import figure_format, pyplot, save
from plansim.units import to_unit

#: SI unit of a compared quantity -> (kind, the unit it is shown in)
DISPLAY = {"1": ("dimensionless", "ppm"), "rad/s": ("angular_rate", "deg/h"),
           "rad/s/(m/s^2)": ("rate_per_acceleration", "deg/h/g")}
#: what each test is, for the headings
TESTS = {
    "misalignment": "gyro misalignments: JJF 2003 7.2.3 rate test vs the chapter's +/- rate turns, eq. (6-8)",
    "accelerometer": "accelerometer cross-axis terms: JJF 2003 multi-position vs the chapter's 8-position test, "
                     "eq. (6-9)",
    "drift": "gyro drift model D0 + D1 aX + D2 aY + D3 aZ: JJF 2003 Bg and G vs the chapter's position test "
             "(Earth rate removed)",
}


def _shown(values, si_unit: str):
    kind, unit = DISPLAY[si_unit]
    return to_unit(values, kind, unit), unit


def chapter_json(result, elapsed: float, version: str) -> dict:
    """The comparison as one JSON-able object, SI units (``unit`` per quantity)."""
    out = {
        "procedure": "chapter", "unit_scenario": result.scenario, "trials": result.trials, "seed": result.seed,
        "path": result.path, "plansim_version": version, "elapsed_s": elapsed,
        "settings": {"turn_rate_rad_s": result.rate, "turns": result.turns, "drift_repeats": result.repeats,
                     "earth_rate_rad_s": result.earth_rate},
        "units": "SI: each quantity's 'unit'; errors are estimate - truth",
        "quantities": result.summary(),
        "random_drift": None,
    }
    if result.random_drift is not None:
        r = result.random_drift
        out["random_drift"] = {
            "equation": "(6-6)", "factor": 2.7, "unit": "rad/s", "repeats": result.repeats,
            "median": [float(v) for v in np.median(r, axis=0)],
            "p2.5": [float(v) for v in np.percentile(r, 2.5, axis=0)],
            "p97.5": [float(v) for v in np.percentile(r, 97.5, axis=0)]}
    return out


def chapter_text(result, elapsed: float) -> str:
    """Per test, a table of each quantity: the unit's mean true value, and per procedure the mean error
    ± its standard uncertainty and the rms error; the better rms marked."""
    lines = [f"plansim run chapter --unit {result.scenario}: {result.trials} trials, seed {result.seed}, path "
             f"{result.path}, {elapsed:.1f} s",
             f"the same simulated units through JJF 2003 and the chapter's tests (turns at +/-"
             f"{math.degrees(result.rate):g} deg/s x{result.turns}; drift positions x{result.repeats}; Earth rate "
             f"removed at {result.earth_rate / (math.pi / 180 / 3600):.5f} deg/h)"]
    rows = result.summary()
    for test, title in TESTS.items():
        chosen = [r for r in rows if r["test"] == test]
        if not chosen:
            continue
        lines += ["", title,
                  f"{'quantity':<11} {'chapter':<14} {'unit':<8} {'true mean':>10} | {'JJF 2003 error':>20} "
                  f"{'rms':>8} | {'chapter error':>20} {'rms':>8}"]
        for r in chosen:
            scale, unit = _shown(1.0, r["unit"])
            j, c = r["jjf2003"], r["chapter"]
            better = "jjf2003" if j["rms"] < c["rms"] else "chapter"
            cells = []
            for name, e in (("jjf2003", j), ("chapter", c)):
                mark = "*" if name == better else " "
                cells.append(f"{e['mean'] * scale:+9.3g} ± {e['u_mean'] * scale:<8.2g} {e['rms'] * scale:8.3g}{mark}")
            lines.append(f"{r['name']:<11} {r['chapter_name']:<14} {unit:<8} {r['truth_mean'] * scale:10.4g} | "
                         f"{cells[0]} | {cells[1]}")
    lines += ["", "error = estimate - truth, mean ± its standard uncertainty (std/sqrt(n)); * the smaller rms"]
    if result.random_drift is not None:
        r, unit = _shown(result.random_drift, "rad/s")
        med = np.median(r, axis=0)
        low, high = np.percentile(r, [2.5, 97.5], axis=0)
        lines += ["", f"random drift, eq. (6-6): 2.7 x std of D0 over {result.repeats} repeats (no true value; its "
                      "distribution over the trials)"]
        for i, axis in enumerate("xyz"):
            lines.append(f"  {axis} gyro: median {med[i]:.3g} {unit}, 95 % of trials in [{low[i]:.3g}, {high[i]:.3g}]")
    return "\n".join(lines)


def chapter_figure(result, path: str | os.PathLike, format: str | None = None) -> None:
    """Per test, the rms error of each quantity by JJF 2003 and by the chapter's procedure, side by side."""
    chosen_format = figure_format(path, format)
    plt = pyplot()
    tests = [t for t in TESTS if t in result.tests]
    fig, axes = plt.subplots(1, len(tests), figsize=(4.5 * len(tests), 3.8), constrained_layout=True, squeeze=False)
    rows = result.summary()
    for ax, test in zip(axes[0], tests):
        chosen = [r for r in rows if r["test"] == test]
        units = sorted({r["unit"] for r in chosen})
        x = np.arange(len(chosen))
        for offset, name, color in ((-0.2, "jjf2003", "tab:blue"), (0.2, "chapter", "tab:orange")):
            values = [_shown(r[name]["rms"], r["unit"])[0] for r in chosen]
            ax.bar(x + offset, values, width=0.4, color=color, label="JJF 2003" if name == "jjf2003" else "chapter")
        ax.set_xticks(x, [r["name"] for r in chosen], rotation=60, fontsize=7)
        ax.set_ylabel("rms error (" + ", ".join(_shown(1.0, u)[1] for u in units) + ")", fontsize=8)
        ax.set_title(test, fontsize=9)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=7)
    fig.suptitle(f"plansim run chapter --unit {result.scenario}: rms error over {result.trials} units "
                 f"(seed {result.seed})", fontsize=10)
    save(fig, path, chosen_format, dpi=110)

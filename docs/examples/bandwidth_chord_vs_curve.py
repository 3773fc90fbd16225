"""JJF 1535-2015 7.2.15: the bandwidth by the chord between two points, or from the fitted curve? (docs/dynamic.md)

7.2.15.1 b) places 8 frequencies evenly up to the expected bandwidth + 10 Hz and inserts one more either side of
it; 7.2.15.2 fits a curve to the scale factor against frequency and reads where it has fallen by 3 dB. For
one-resonance gyros of several dampings (f_n = 100 Hz, the grid planned for the true bandwidth rounded to 10 Hz),
this prints the noise-free reading of each estimator against the analytic bandwidth: the chord's error grows with
the response's curvature at the crossing; the curve (``bandwidth_curve_fit``) has none. With ``--trials N`` it
also runs ``plansim run jjf1537``'s Monte Carlo for the lightest damping and prints both estimators' bias and
scatter.

    python docs/examples/bandwidth_chord_vs_curve.py [--trials N]
"""

from __future__ import annotations

import argparse

from plansim.estimate.dynamic import bandwidth_3db, bandwidth_curve_fit
from plansim.model.dynamics import second_order_bandwidth, second_order_magnitude
from plansim.schedule.jjf1537 import jjf1535_frequencies

NATURAL_FREQUENCY = 100.0  # Hz
DAMPINGS = (0.3, 0.5, 0.7, 1.0, 1.5)


def main(trials: int) -> None:
    print(" zeta   f_3dB (Hz)   grid planned for   chord error (Hz)   curve error (Hz)")
    for zeta in DAMPINGS:
        truth = second_order_bandwidth(NATURAL_FREQUENCY, zeta)
        frequencies = jjf1535_frequencies(round(truth, -1))
        ratios = second_order_magnitude(frequencies, NATURAL_FREQUENCY, zeta)
        ratios = ratios / ratios[0]  # eq. (9): S_0 read at the lowest frequency
        chord = bandwidth_3db(frequencies, ratios) - truth
        curve = bandwidth_curve_fit(frequencies, ratios).bandwidth - truth
        print(f"{zeta:5.2f}   {truth:10.3f}   {round(truth, -1):13.0f} Hz   {chord:+16.4f}   {curve:+16.2e}")
    if trials:
        from plansim.simulate.jjf1537 import run_jjf1537
        from plansim.simulate.vibration_table import Jjf1537Experiment

        zeta = DAMPINGS[0]
        expected = round(second_order_bandwidth(NATURAL_FREQUENCY, zeta), -1)
        result = run_jjf1537(Jjf1537Experiment(damping=zeta, expected_bandwidth=expected), trials=trials, seed=7)
        s = result.summary()
        print(f"\nMonte Carlo, zeta {zeta}, {trials} trials (noise 0.5 deg/sqrt(h), 16-bit output):")
        print(f"  chord: bias {s['bandwidth_bias']:+.4f} Hz, s {s['bandwidth_std']:.4f} Hz")
        print(f"  curve: bias {s['bandwidth_fit_bias']:+.4f} Hz, s {s['bandwidth_fit_std']:.4f} Hz "
              f"(GUM u {result.gum['bandwidth_fit']:.4f} Hz)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=0, help="Monte Carlo trials for the lightest damping (0: none)")
    main(parser.parse_args().trials)

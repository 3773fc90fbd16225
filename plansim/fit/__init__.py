"""Fitting a recording (simulated or measured): identifiability, estimates, noise and uncertainty from the data.

- :func:`~plansim.fit.joint.fit_recording` — the whole fit (docs/fitting.md); :func:`~plansim.fit.joint.recording_noise`
  — the samples' noise, which refits of one recording share (:func:`~plansim.fit.joint.recording_noise_models`:
  under both models of a static mean's quantisation error, from one pass);
- :func:`~plansim.fit.site.resolve_site` — the site from the command line, the recording or the scenario;
  :func:`~plansim.fit.site.scenario_fit_options` — the fit's options from a lab's scenario;
- :mod:`~plansim.fit.model` — the segment means by the simulator's physics; :mod:`~plansim.fit.identify` —
  which parameters the segments identify; :mod:`~plansim.fit.noise` — Allan deviation and scatter;
  :mod:`~plansim.fit.result` — the JSON object and the NetCDF Dataset.

A layer between ``io`` (above: files) and ``uncertainty`` (below: the GUM machinery): it reads no file.
"""

from plansim.fit.joint import FitResult, fit_recording, recording_noise, recording_noise_models
from plansim.fit.site import TABLE_1_TURNTABLE, Site, resolve_site, scenario_fit_options

__all__ = ["TABLE_1_TURNTABLE", "FitResult", "Site", "fit_recording", "recording_noise", "recording_noise_models",
           "resolve_site", "scenario_fit_options"]

"""Compilation hygiene of the numba kernels: each is compiled once, whatever calls it.

numba types a Python ``int``/``bool`` literal passed from one kernel to another as a *literal* type
and compiles the callee once per distinct value; an accumulator that starts as ``J = 0`` is typed
``Literal[int](0)`` before it becomes ``int64`` and compiles the callee a second time. Each copy
costs a full compile (1–2 s for the output model), which is why the kernels pass numpy scalars
(``np.int64``, ``np.bool_``) instead. This test compiles every kernel from an empty cache in a fresh
process (kernels loaded from the cache never compile their callees, so a warm process would see
nothing) and fails on any kernel with more than one compiled signature.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

_EXERCISE_EVERY_KERNEL = textwrap.dedent("""
    import importlib, json, pkgutil
    import numba
    import plansim.kernels
    from plansim.io.scenario_file import load_scenario
    from plansim.simulate.arguments import nominal_draws, noise_free_segment_means
    from plansim.simulate.chunks import simulate_recording, simulate_segment_means
    from plansim.uncertainty.sensitivities import segment_mean_derivatives

    scenario = load_scenario("jjf2003")
    simulate_segment_means(scenario, 3, 1, path="segment")
    simulate_segment_means(scenario, 3, 1, path="sample")
    simulate_recording(scenario, 1)
    noise_free_segment_means(scenario, nominal_draws(scenario)[None])
    segment_mean_derivatives(scenario, [0, 60], [1e-3, 1e-5])
    copies = {}
    for module_info in pkgutil.iter_modules(plansim.kernels.__path__):
        module = importlib.import_module("plansim.kernels." + module_info.name)
        for name, value in vars(module).items():
            if isinstance(value, numba.core.registry.CPUDispatcher) and value.__module__ == module.__name__:
                copies[module.__name__ + "." + name] = [str(s) for s in value.signatures]
    from plansim.kernels import segment_path
    loaded = {name: getattr(segment_path, name).stats.cache_hits for name in
              ("simulate_chunk_nodes", "simulate_chunk_statistics")}
    print(json.dumps({"copies": copies, "loaded_from_cache": {k: sum(v.values()) for k, v in loaded.items()}}))
""")


@pytest.fixture(scope="module")
def cold_start_report(tmp_path_factory) -> dict:
    """Run every kernel once in a fresh process with an empty cache (everything compiles there)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path_factory.mktemp("numba-cache")))
    done = subprocess.run([sys.executable, "-c", _EXERCISE_EVERY_KERNEL], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_every_kernel_is_compiled_once(cold_start_report):
    compiled = {name: signatures for name, signatures in cold_start_report["copies"].items() if signatures}
    assert len(compiled) >= 10, f"too few kernels compiled to mean anything: {sorted(compiled)}"
    duplicated = {name: signatures for name, signatures in compiled.items() if len(signatures) > 1}
    assert not duplicated, "kernels compiled more than once (literal arguments?):\n" + json.dumps(duplicated, indent=1)


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="one core: the kernels are compiled one after the other")
def test_a_cold_start_compiles_the_two_segment_kernels_in_two_processes(cold_start_report):
    """From an empty cache, one segment kernel is compiled here and the other by a second process:
    this process then finds that one in the cache (one cache hit) and compiles the other (none)."""
    loaded = cold_start_report["loaded_from_cache"]
    assert sorted(loaded.values()) == [0, 1], loaded

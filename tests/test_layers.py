"""The package's layers: the map in docs/index.md, the import-linter contract and the kernels' imports agree.

`lint-imports` (run by .ci/run) checks the imports against the contract in pyproject.toml; these tests
check that the contract is the one the documentation states, that it names every top-level module of
the package, and that the kernels import nothing but numpy, numba and math.
"""

from __future__ import annotations

import ast
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "plansim"


def _contract(contract_id: str) -> dict:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        config = tomllib.load(fh)["tool"]["importlinter"]
    (contract,) = [c for c in config["contracts"] if c["id"] == contract_id]
    return contract


def _documented_layers() -> list[str]:
    text = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```layers\n(.*?)^```", text, flags=re.M | re.S)
    assert len(blocks) == 1, "docs/index.md must hold exactly one ```layers block"
    return [line.strip() for line in blocks[0].splitlines() if line.strip()]


def test_the_documented_layer_map_is_the_enforced_contract():
    contract = _contract("layers")
    assert contract["type"] == "layers" and contract["containers"] == ["plansim"]
    assert _documented_layers() == contract["layers"]


def test_the_contract_names_every_top_level_module():
    contract = _contract("layers")
    named = {name.strip() for layer in contract["layers"] for name in layer.split("|")}
    modules = {p.stem for p in PACKAGE.glob("*.py") if p.name != "__init__.py"}
    modules |= {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert modules == named, f"not in the contract: {sorted(modules - named)}; gone: {sorted(named - modules)}"


def test_the_distribution_ships_every_package():
    """pyproject's package list is every folder of plansim/ with an __init__.py, and the scenarios: a
    package left out is missing from a wheel (``pip install .``), not from the editable install the
    tests run on (plansim.cli was, so the installed ``plansim`` command could not start)."""
    with open(ROOT / "pyproject.toml", "rb") as fh:
        listed = set(tomllib.load(fh)["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in PACKAGE.rglob("__init__.py")}
    assert listed == found | {"plansim.scenarios"}, (
        f"missing from [tool.setuptools] packages: {sorted(found - listed)}; "
        f"listed but absent: {sorted(listed - found - {'plansim.scenarios'})}")


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path.name}: relative import"
            found.add(node.module)
    return found


def test_kernels_import_only_numpy_numba_and_math():
    allowed = {"__future__", "math", "numpy", "numba"}
    options_allowed = allowed | {"hashlib", "os", "pathlib"}  # the cache folder: environment and source hash
    for path in sorted((PACKAGE / "kernels").glob("*.py")):
        outside = {name for name in _imports(path)
                   if name.split(".")[0] not in (options_allowed if path.name == "options.py" else allowed)
                   and not name.startswith("plansim.kernels")}
        assert not outside, f"plansim/kernels/{path.name} imports {sorted(outside)}"


def test_the_kernel_layout_matches_the_parameter_order():
    """kernels/layout.py names the parameter vector's blocks; model/parameters.py defines the order."""
    from plansim.kernels import layout
    from plansim.model.parameters import PARAMETER_NAMES

    assert len(PARAMETER_NAMES) == layout.N_TRUTH
    for first, group in ((layout.KG_FIRST, "Kg"), (layout.G_FIRST, "g"), (layout.KA_FIRST, "Ka")):
        assert [PARAMETER_NAMES[first + 3 * i + j] for i in range(3) for j in range(3)] == \
            [f"{group}{a}{b}" for a in "xyz" for b in "xyz"]
    assert list(PARAMETER_NAMES[layout.BG_FIRST:layout.BG_FIRST + 3]) == ["Bgx", "Bgy", "Bgz"]
    assert list(PARAMETER_NAMES[layout.BA_FIRST:layout.BA_FIRST + 3]) == ["Bax", "Bay", "Baz"]
    assert [PARAMETER_NAMES[layout.P_FIRST + k] for k in range(6)] == \
        [f"p{'xyz'[i]}{'xyz'[j]}" for i, j in layout.P_ENTRIES]
    assert layout.TRUTH == slice(0, layout.N_TRUTH) and layout.FIXTURE.start == layout.N_TRUTH
    assert layout.PERPENDICULARITY.stop == layout.HEAD
    assert layout.SEG_PHASE == layout.PER_SEGMENT - 1


def test_no_numba_outside_the_kernels():
    """Every numba function lives in plansim/kernels (numba options in one module)."""
    for path in sorted(PACKAGE.rglob("*.py")):
        if "kernels" in path.parts:
            continue
        text = path.read_text(encoding="utf-8")
        assert not re.search(r"@(numba\.)?(n?jit|vectorize|guvectorize)\b|numba\.n?jit\(", text), \
            f"{path.relative_to(ROOT)} defines a numba function"

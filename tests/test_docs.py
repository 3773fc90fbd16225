"""The repository stands alone: its documentation and code cite the specification, not notes kept elsewhere.

Users get the repository and nothing else. So no file under ``docs/``, ``scenarios/`` or
``plansim/``, nor ``README.md``, may mention a "digest" (the project's private English notes on the
source documents) or a path into the ``shared`` folder beside the repository; they cite JJF 2003-2022
by clause, equation, table or Appendix A item, and ``docs/specification.md`` states what they rely on.
Every relative link in ``docs/*.md`` and ``README.md`` must point to a file inside the repository,
and an anchor in a link to a Markdown page must name one of that page's headings. The files and
Python names the pages quote (``plansim/kernels/physics.py``, ``plansim.config.parse_scenario``,
``from plansim.io.scenario_file import load_scenario``) must exist, so a page does not send its
reader to a module that has moved.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SEARCHED = ("docs", "README.md", "scenarios", "plansim")

# "digest" as a word, so that hashlib's hexdigest() is not an offence
DIGEST = re.compile(r"\bdigests?\b", re.IGNORECASE)
# a path out of the repository into the shared folder of the project's workspace
SHARED_PATH = re.compile(r"(?:\.\./)+shared\b|/work/shared\b|\bshared/(?:spec|seeds)\b")

LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE_DEFINITION = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$", re.MULTILINE)
FENCE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1", re.DOTALL)
HEADING = re.compile(r"^#{1,6}[ \t]+(.+?)[ \t]*#*[ \t]*$", re.MULTILINE)
CODE_SPAN = re.compile(r"`([^`\n]+)`")
REPOSITORY_PATH = re.compile(r"(?:plansim|tests|scenarios|benchmarks|docs)/[\w./-]*\w")
DOTTED_NAME = re.compile(r"(plansim(?:\.[A-Za-z_]\w*)+)(?:\(.*\))?")
PYTHON_IMPORT = re.compile(r"^\s*(?:>>>\s*)?(?:from\s+(plansim[\w.]*)\s+import\s+([\w, ]+)|import\s+(plansim[\w.]*))"
                           r"\s*(?:#.*)?$", re.MULTILINE)


def text_files(entry: str) -> list[Path]:
    """The text files under one searched entry (a file or a folder), caches left out."""
    path = ROOT / entry
    candidates = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    files = []
    for candidate in candidates:
        if "__pycache__" in candidate.parts or candidate.suffix in (".pyc", ".nbi", ".nbc"):
            continue
        try:
            candidate.read_text(encoding="utf-8")
        except UnicodeDecodeError:  # a binary file (a figure, a NetCDF example) says nothing
            continue
        files.append(candidate)
    return files


def offences(text: str) -> list[str]:
    """Lines of ``text`` that cite the digest or a path into the shared folder, as ``line N: …``."""
    return [f"line {number}: {line.strip()}" for number, line in enumerate(text.splitlines(), start=1)
            if DIGEST.search(line) or SHARED_PATH.search(line)]


def without_code(markdown: str) -> str:
    """Markdown with fenced blocks and inline code spans blanked (a link there is only an example)."""
    return INLINE_CODE.sub("", FENCE.sub("", markdown))


def relative_targets(markdown: str) -> list[str]:
    """The targets of every inline link, image and reference definition that is not a URL."""
    text = without_code(markdown)
    targets = LINK.findall(text) + REFERENCE_DEFINITION.findall(text)
    return [t for t in targets if not re.match(r"[A-Za-z][A-Za-z0-9+.-]*:", t)]  # http:, https:, mailto:, …


def heading_anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but ``-`` and ``_`` dropped, spaces to ``-``."""
    heading = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link in a heading keeps its text
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(markdown: str) -> set[str]:
    """Every anchor a Markdown page defines through its headings (repeats get -1, -2, … as on GitHub)."""
    seen: dict[str, int] = {}
    out = set()
    for heading in HEADING.findall(FENCE.sub("", markdown)):
        anchor = heading_anchor(heading)
        count = seen.get(anchor, 0)
        out.add(anchor if count == 0 else f"{anchor}-{count}")
        seen[anchor] = count + 1
    return out


def python_name_exists(dotted: str) -> bool:
    """Whether ``plansim.a.b.c`` names a module, or an attribute reached from the longest importable module."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[cut:]:
            if not hasattr(found, attribute):
                return False
            found = getattr(found, attribute)
        return True
    return False


def quoted_names(markdown: str) -> tuple[list[str], list[str]]:
    """The repository paths and the ``plansim`` Python names a page quotes in code spans and Python blocks."""
    paths, names = [], []
    for span in CODE_SPAN.findall(FENCE.sub("", markdown)):
        if REPOSITORY_PATH.fullmatch(span) and "*" not in span:
            paths.append(span)
        elif match := DOTTED_NAME.fullmatch(span):
            names.append(match.group(1))
    for block in re.findall(r"^```(?:python|pycon)[ \t]*\n(.*?)^```", markdown, re.MULTILINE | re.DOTALL):
        for module, imported, plain in PYTHON_IMPORT.findall(block):
            names += [plain] if plain else [f"{module}.{name.strip()}" for name in imported.split(",") if name.strip()]
    return paths, names


def markdown_pages() -> list[Path]:
    return sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]


def page_id(page: Path) -> str:
    return page.relative_to(ROOT).as_posix()


# ----------------------------------------------------------------------------- the detectors themselves


def test_the_detectors_catch_what_they_are_for_and_nothing_else():
    assert offences("the sign of eq. (12) (digest §1.4)") == ["line 1: the sign of eq. (12) (digest §1.4)"]
    assert offences("ok\nSee the Digest.") == ["line 2: See the Digest."]
    assert offences("see ../shared/spec/notes.md") and offences("/work/shared/seeds/003.txt")
    assert offences("from shared/seeds/ (the originals)")
    assert offences("folder = f'numba-{source_hash.hexdigest()[:16]}'") == []
    assert offences("JJF 2003-2022 §7.2.2, eq. (6); shared by several engineers") == []
    assert relative_targets("[a](model.md#frames) ![f](fig.png) [w](https://example.org) `[c](code.md)`\n"
                            "```\n[d](fenced.md)\n```\n[r]: ../elsewhere.md\n") == [
        "model.md#frames", "fig.png", "../elsewhere.md"]
    assert heading_anchor("The calibration model (JJF 2003 eq. (1) and (2))") == \
        "the-calibration-model-jjf-2003-eq-1-and-2"
    assert heading_anchor("## `[reduction]`".lstrip("# ")) == "reduction"
    assert anchors("# A\n## B b\n## B b\n```\n# not a heading\n```\n") == {"a", "b-b", "b-b-1"}
    paths, names = quoted_names("`plansim/kernels/physics.py` and `plansim.run(scenario)`, `scenarios/*.toml`\n"
                                "```python\nimport plansim\nfrom plansim.config import parse_scenario, Scenario\n"
                                "```\n```console\n$ from plansim.x import y\n```\n")
    assert paths == ["plansim/kernels/physics.py"]
    assert names == ["plansim.run", "plansim", "plansim.config.parse_scenario", "plansim.config.Scenario"]
    assert python_name_exists("plansim.config.parse_scenario") and python_name_exists("plansim.kernels.physics")
    assert not python_name_exists("plansim.scenario.parse_scenario")
    assert not python_name_exists("plansim.config.no_such_function")


# ----------------------------------------------------------------------------- the repository stands alone


@pytest.mark.parametrize("entry", SEARCHED)
def test_no_file_cites_the_digest_or_a_path_into_the_shared_folder(entry):
    found = []
    for path in text_files(entry):
        name = path.relative_to(ROOT).as_posix()
        found += [f"{name} {where}" for where in offences(path.read_text(encoding="utf-8"))]
    assert not found, ("cite JJF 2003-2022 by clause/equation/table/Appendix A item (docs/specification.md) "
                       "instead of the digest or a path outside the repository:\n" + "\n".join(found))


@pytest.mark.parametrize("page", markdown_pages(), ids=page_id)
def test_every_relative_link_points_to_a_file_in_the_repository(page):
    broken = []
    for target in relative_targets(page.read_text(encoding="utf-8")):
        path = target.split("#", 1)[0].split("?", 1)[0]
        if not path:
            continue  # an anchor in the same page: checked below
        resolved = (page.parent / path).resolve()
        if not resolved.is_relative_to(ROOT):
            broken.append(f"{target} (outside the repository)")
        elif not resolved.exists():
            broken.append(f"{target} (no such file)")
    assert not broken, f"{page_id(page)}: " + "; ".join(broken)


@pytest.mark.parametrize("page", markdown_pages(), ids=page_id)
def test_every_anchor_in_a_link_names_a_heading_of_its_page(page):
    broken = []
    for target in relative_targets(page.read_text(encoding="utf-8")):
        path, _, fragment = target.partition("#")
        destination = (page.parent / path).resolve() if path else page
        if not fragment or destination.suffix != ".md" or not destination.is_file():
            continue  # no anchor, not a Markdown page, or a missing file (the test above reports it)
        if fragment not in anchors(destination.read_text(encoding="utf-8")):
            broken.append(target)
    assert not broken, f"{page_id(page)}: no heading for " + ", ".join(broken)


@pytest.mark.parametrize("page", markdown_pages(), ids=page_id)
def test_every_file_and_python_name_a_page_quotes_exists(page):
    paths, names = quoted_names(page.read_text(encoding="utf-8"))
    missing = [path for path in paths if not (ROOT / path).exists()]
    missing += [name for name in names if not python_name_exists(name)]
    assert not missing, (f"{page_id(page)} quotes what the repository does not have: "
                         + ", ".join(dict.fromkeys(missing)))

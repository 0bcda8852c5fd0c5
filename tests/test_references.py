"""Every citation key in the package's docstrings has an entry in docs/references.md.

A key is cited as ``[Key]`` (e.g. ``[Tien2011]``); the references page gives each entry a
``## Key`` heading. The test reads the checkout's sources (BALLBAL_REPO, since the tests
run from a copy)."""

import ast
import os
import pathlib
import re

REPO = pathlib.Path(os.environ.get("BALLBAL_REPO") or pathlib.Path(__file__).resolve().parents[1])
PACKAGE = REPO / "python" / "ballbal"
REFERENCES = REPO / "docs" / "references.md"

# A citation: a bracketed key of a capital and at least three more letters (then perhaps
# a year), not an index, a type argument or a unit (``list[Balancer]`` is preceded by a
# word character, ``[0]`` has no letter, ``[Pa]`` is too short).
CITATION = re.compile(r"(?<![\w\]`])\[([A-Z][A-Za-z]{3,}[0-9]{0,4}[a-z]?)\](?!\()")


def docstrings(path: pathlib.Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                out.append(doc)
    return out


def cited_keys() -> dict[str, set[str]]:
    cited: dict[str, set[str]] = {}
    for path in sorted(PACKAGE.glob("*.py*")):
        if path.suffix not in (".py", ".pyi"):
            continue
        for doc in docstrings(path):
            for key in CITATION.findall(doc):
                cited.setdefault(key, set()).add(path.name)
    return cited


def entries() -> set[str]:
    text = REFERENCES.read_text(encoding="utf-8")
    return set(re.findall(r"^## ([A-Za-z][A-Za-z0-9]*)\s*$", text, flags=re.M))


def test_references_page_lists_the_seven_sources() -> None:
    assert REFERENCES.exists(), f"{REFERENCES}: set BALLBAL_REPO to the repository checkout"
    keys = entries()
    # Tien (2011) the planar model follows and the ball-spring/tilt paper at least.
    assert {"Tien2011", "Rezaee2017"} <= keys, keys
    # and the oil law's two (Stokes' drag and the tube's wall factor)
    assert {"Stokes1851", "HabermanSayre1958"} <= keys, keys
    assert len(keys) == 7, keys


def test_every_cited_key_has_an_entry() -> None:
    assert PACKAGE.is_dir(), f"{PACKAGE}: set BALLBAL_REPO to the repository checkout"
    cited = cited_keys()
    # The package cites its sources by key; an empty set would mean the pattern broke.
    assert "Tien2011" in cited, sorted(cited)
    missing = {k: sorted(v) for k, v in cited.items() if k not in entries()}
    assert not missing, f"citation keys without an entry in docs/references.md: {missing}"


def test_the_pattern_finds_a_citation_and_skips_indexing() -> None:
    text = "as [Tien2011] shows; list[Balancer], x[0], 3 [Pa], [Note](url) and ``[Key]``"
    assert CITATION.findall(text) == ["Tien2011"]

"""The documentation site: every public name documented and in the reference, and the
built site opened in headless Chromium.

The site is built by ``scripts/docs.sh`` (Sphinx, warnings as errors). scripts/test.sh
builds it before pytest and passes its location in ``BALLBAL_DOCS_HTML``; without that
variable this module uses ``$BALLBAL_REPO/docs/_build/html`` if present, and otherwise
builds it (small gallery, a few minutes). The browser checks need Debian's
``chromium`` (``.ci/run`` installs it); without it they fail, saying so."""

from __future__ import annotations

import html.parser
import inspect
import os
import pathlib
import shutil
import subprocess
import sys
import types
import urllib.parse

import numpy as np
import pytest

import ballbal

REPO = pathlib.Path(os.environ.get("BALLBAL_REPO") or pathlib.Path(__file__).resolve().parents[1])


@pytest.fixture(scope="module")
def site() -> pathlib.Path:
    given = os.environ.get("BALLBAL_DOCS_HTML")
    root = pathlib.Path(given) if given else REPO / "docs" / "_build" / "html"
    if not (root / "index.html").exists():
        if given:
            pytest.fail(f"BALLBAL_DOCS_HTML={given} has no index.html")
        env = {**os.environ, "PYTHON": sys.executable}
        subprocess.run(["bash", str(REPO / "scripts" / "docs.sh")], check=True, env=env)
    assert (root / "index.html").exists(), root
    return root


def documented_modules() -> dict[str, types.ModuleType]:
    """The package and the submodules ``ballbal.__all__`` names: the API reference's
    promise (independent of docs/api_pages.py, which writes the pages)."""
    mods = {"ballbal": ballbal}
    for name in ballbal.__all__:
        obj = getattr(ballbal, name)
        if isinstance(obj, types.ModuleType):
            mods[obj.__name__] = obj
    return mods


def public(module: types.ModuleType) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items()
                 if not n.startswith("_") and (inspect.isclass(v) or inspect.isfunction(v))
                 and v.__module__ == module.__name__]
    return [n for n in names if n != "__version__"
            and not isinstance(getattr(module, n), types.ModuleType)]


def attribute_docs(module: types.ModuleType) -> set[str]:
    """Names of module-level data documented by a ``#:`` comment or a docstring after the
    assignment (what autodoc shows for a constant)."""
    from sphinx.pycode import ModuleAnalyzer

    docs = ModuleAnalyzer.for_module(module.__name__).find_attr_docs()
    return {name for (scope, name), lines in docs.items() if scope == "" and any(lines)}


def test_every_public_name_has_a_docstring() -> None:
    missing = []
    for modname, mod in documented_modules().items():
        if not (mod.__doc__ or "").strip():
            missing.append(modname)
        for name in public(mod):
            obj = getattr(mod, name)
            if inspect.isclass(obj) or callable(obj):
                if not (obj.__doc__ or "").strip():
                    missing.append(f"{modname}.{name}")
                if inspect.isclass(obj):
                    for attr, member in vars(obj).items():
                        fn = member
                        if isinstance(member, (classmethod, staticmethod)):
                            fn = member.__func__
                        method = inspect.isfunction(fn) or isinstance(fn, property)
                        if attr.startswith("_") or not method:
                            continue
                        if not (fn.__doc__ or "").strip():
                            missing.append(f"{modname}.{name}.{attr}")
            else:
                # Data: documented where it is defined (``#:`` above the assignment).
                owner = mod
                if name not in attribute_docs(owner):
                    missing.append(f"{modname}.{name} (data, no #: comment)")
    assert not missing, f"public names without documentation: {missing}"


def test_every_public_name_has_a_reference_page(site: pathlib.Path) -> None:
    generated = site / "api" / "generated"
    missing = []
    for modname, mod in documented_modules().items():
        if not (site / "api" / f"{modname}.html").exists():
            missing.append(f"module page {modname}")
        for name in public(mod):
            if not (generated / f"{modname}.{name}.html").exists():
                missing.append(f"{modname}.{name}")
    assert not missing, f"public names missing from the API reference: {missing}"


class Links(html.parser.HTMLParser):
    """hrefs, image sources and element ids of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.hrefs: list[str] = []
        self.images: list[str] = []
        self.ids: set[str] = set()
        self.title = ""
        self._in_title = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"] or "")
        if tag == "a" and a.get("href"):
            self.hrefs.append(a["href"] or "")
        if tag == "img" and a.get("src"):
            self.images.append(a["src"] or "")
        if tag == "title":
            self._in_title = True

    def handle_endtag(self, tag: str) -> None:
        if tag == "title":
            self._in_title = False

    def handle_data(self, data: str) -> None:
        if self._in_title:
            self.title += data


def parse(path: pathlib.Path) -> Links:
    p = Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


def internal(ref: str) -> bool:
    scheme = urllib.parse.urlsplit(ref).scheme
    return not scheme and not ref.startswith("//")


def test_no_broken_internal_links_or_images(site: pathlib.Path) -> None:
    pages = sorted(site.rglob("*.html"))
    assert len(pages) > 50, len(pages)
    parsed = {p: parse(p) for p in pages}
    broken = []
    for page, links in parsed.items():
        for ref in links.hrefs + links.images:
            if not internal(ref):
                continue
            parts = urllib.parse.urlsplit(ref)
            target = page
            if parts.path:
                target = (page.parent / urllib.parse.unquote(parts.path)).resolve()
            if target.is_dir():
                target = target / "index.html"
            if not target.exists():
                broken.append(f"{page.relative_to(site)} -> {ref}")
            elif parts.fragment and target.suffix == ".html":
                ids = parsed[target].ids if target in parsed else parse(target).ids
                if urllib.parse.unquote(parts.fragment) not in ids:
                    broken.append(f"{page.relative_to(site)} -> {ref} (no such anchor)")
    assert not broken, f"{len(broken)} broken internal links: {broken[:20]}"


def chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.fail("headless Chromium is needed for the documentation's browser test: "
                    "apt-get install -y chromium (.ci/run installs it)")
    return exe


def shoot(url: str, png: pathlib.Path) -> None:
    # --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start.
    subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu",
                    "--hide-scrollbars", "--window-size=1280,1000",
                    f"--screenshot={png}", url],
                   check=True, capture_output=True, timeout=120)


def rendered_title(url: str) -> str:
    out = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu",
                          "--dump-dom", url], check=True, capture_output=True, text=True,
                         timeout=120).stdout
    p = Links()
    p.feed(out)
    return p.title


@pytest.mark.parametrize("page, title", [
    ("index.html", "ballbal"),
    ("api/generated/ballbal.Balancer.html", "ballbal.Balancer"),
    ("auto_gallery/omega_eta_maps.html", "Omega-eta maps"),
])
def test_pages_render_in_chromium(site: pathlib.Path, tmp_path: pathlib.Path, page: str,
                                  title: str) -> None:
    import matplotlib.image

    path = site / page
    assert path.exists(), path
    assert title in parse(path).title
    url = path.resolve().as_uri()
    # The title after the page's scripts ran, as the browser holds it.
    assert title in rendered_title(url)
    png = tmp_path / (page.replace("/", "_") + ".png")
    shoot(url, png)
    if os.environ.get("BALLBAL_DOCS_SCREENSHOTS"):
        keep = pathlib.Path(os.environ["BALLBAL_DOCS_SCREENSHOTS"])
        keep.mkdir(parents=True, exist_ok=True)
        shutil.copy(png, keep / png.name)
    img = matplotlib.image.imread(png)
    assert img.shape[0] >= 900 and img.shape[1] >= 1200, img.shape
    grey = img[..., :3].mean(axis=2)
    # A blank (all-white or all-black) page has no variance; a page of text and figures
    # has plenty (a rendered page measures above 0.05 in the unit brightness scale).
    assert grey.std() > 0.02, grey.std()
    # Not mostly one colour: text occupies a fair share of the rows.
    assert np.mean(grey.std(axis=1) > 0.01) > 0.2
    # The page's images were found by the browser too: each is a file of the site.
    for src in parse(path).images:
        if internal(src):
            assert (path.parent / urllib.parse.unquote(src)).resolve().stat().st_size > 0, src


def howto_blocks() -> list[tuple[str, int, str]]:
    """(page, line, code) of every Python block of the how-to pages; a block whose first
    line is ``# slow: ...`` (minutes) or ``# not run: ...`` (it needs the reader's own
    data, which it names) is left to the reader."""
    import re

    out = []
    for page in sorted((REPO / "docs" / "howto").glob("*.md")):
        text = page.read_text(encoding="utf-8")
        for m in re.finditer(r"```python\n(.*?)```", text, re.S):
            if not m.group(1).startswith(("# slow:", "# not run:")):
                out.append((page.name, text[: m.start()].count("\n") + 1, m.group(1)))
    return out


@pytest.mark.parametrize("page, line, code", howto_blocks(),
                         ids=[f"{p}:{n}" for p, n, _ in howto_blocks()])
def test_howto_blocks_run_as_pasted(tmp_path: pathlib.Path, page: str, line: int,
                                    code: str) -> None:
    # A fresh interpreter in an empty directory: a block may use only what it defines.
    script = tmp_path / "block.py"
    script.write_text(code, encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    p = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, f"{page}:{line} failed:\n{p.stderr[-2000:]}"

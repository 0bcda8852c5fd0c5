"""Writes the API reference's source pages from the installed package's ``__all__``.

One page for the top-level package (its names that are not modules) and one for each
public submodule listed in ``ballbal.__all__``; each lists the module's public names in
an autosummary table whose entries get their own generated pages. Nothing here is a
hand-kept list of names: a name added to an ``__all__`` appears at the next build."""

from __future__ import annotations

import importlib
import inspect
import pathlib
import pkgutil
import types

import ballbal


def public_names(module: types.ModuleType) -> list[str]:
    """The module's ``__all__``, or (for a module without one) the names it defines and
    does not mark private."""
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items()
                 if not n.startswith("_") and not inspect.ismodule(v)
                 and getattr(v, "__module__", module.__name__) == module.__name__
                 and (inspect.isclass(v) or inspect.isfunction(v))]
    return sorted(n for n in names if n != "__version__")


def public_modules() -> dict[str, types.ModuleType]:
    """``ballbal`` and every submodule whose name does not start with ``_``, by full
    name (the ones ``ballbal.__all__`` names first)."""
    mods = {"ballbal": ballbal}
    for name in ballbal.__all__:
        obj = getattr(ballbal, name)
        if inspect.ismodule(obj):
            mods[obj.__name__] = obj
    for info in sorted(pkgutil.iter_modules(ballbal.__path__), key=lambda i: i.name):
        if not info.name.startswith("_"):
            full = f"ballbal.{info.name}"
            mods.setdefault(full, importlib.import_module(full))
    return mods


def reference_entries() -> dict[str, list[str]]:
    """Module name -> the public names that get a reference page there. A submodule that
    ``ballbal.__all__`` does not name lists only what the top level does not re-export
    (``ballbal.model.Balancer`` is documented once, as ``ballbal.Balancer``)."""
    top = {id(getattr(ballbal, n)) for n in ballbal.__all__}
    out = {}
    for modname, mod in public_modules().items():
        listed = modname == "ballbal" or modname.split(".")[-1] in ballbal.__all__
        names = [n for n in public_names(mod) if not inspect.ismodule(getattr(mod, n))]
        if not listed:
            names = [n for n in names if id(getattr(mod, n)) not in top]
        if names:
            out[modname] = names
    return out


def _page(modname: str, names: list[str]) -> str:
    title = f"``{modname}``"
    # ``ballbal.scan`` is both a module and the function the package exports: the
    # function keeps the name as a link target.
    shadowed = not isinstance(getattr(ballbal, modname.rpartition(".")[2], None), types.ModuleType)
    lines = [title, "=" * len(title), "",
             f".. automodule:: {modname}", "   :no-members:",
             *(["   :no-index:"] if shadowed and modname != "ballbal" else []), "",
             f".. currentmodule:: {modname}", "",
             ".. autosummary::", "   :toctree: generated/", "   :nosignatures:", ""]
    lines += [f"   {n}" for n in names]
    return "\n".join(lines) + "\n"


def write_api_pages(dest: pathlib.Path) -> None:
    """Write ``dest/index.rst`` and one page per public module (only when changed, so
    Sphinx does not rebuild them needlessly)."""
    dest.mkdir(parents=True, exist_ok=True)
    entries = reference_entries()
    pages = {"index.rst": "\n".join([
        "API reference", "=============", "",
        "Every public name of the package, from its docstring. The top-level package",
        "re-exports the everyday names; the submodules hold the rest.", "",
        ".. toctree::", "   :maxdepth: 1", "", *[f"   {m}" for m in entries]]) + "\n"}
    for modname, names in entries.items():
        pages[f"{modname}.rst"] = _page(modname, names)
    for name, text in pages.items():
        path = dest / name
        if not path.exists() or path.read_text() != text:
            path.write_text(text)

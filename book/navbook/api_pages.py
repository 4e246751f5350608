"""The API reference pages (``python -m navbook api-modules``): every module of navlib and navbook, one
page per layer.

``api-modules --out FILE``
    Write the API reference: an overview to FILE and one page per layer of ``navlib`` beside it
    (``api_<layer>.md``: a summary table of its modules, then their ``automodule`` sections).
"""

from __future__ import annotations

import importlib
import pkgutil
import re
from pathlib import Path

import navlib

import navbook

from .landing import _md_cell


def navlib_modules() -> list[str]:
    """Every module of the ``navlib`` package, then of the book's tooling ``navbook`` (``__main__``
    excluded), top-level modules first."""
    names = []
    for pkg in (navlib, navbook):
        mods = [
            m.name
            for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")
            if not m.name.endswith("__main__")
        ]
        names += sorted(mods, key=lambda n: (n.count("."), n))
    return names


def api_markdown(modules: list[str]) -> str:
    """One section per module (MyST markdown): a heading and an ``automodule`` directive, in an
    ``eval-rst`` block because autodoc emits reStructuredText."""
    parts = []
    for name in modules:
        parts += [
            f"## `{name}`",
            "",
            "```{eval-rst}",
            f".. automodule:: {name}",
            "   :members:",
            "```",
            "",
        ]
    return "\n".join(parts)


#: The API reference's pages, one per layer of navlib, in the order the sidebar shows them: (page name,
#: title, module prefixes).  A module matches the longest prefix; the book's build tooling comes last.
API_LAYERS = (
    ("sensors", "Sensors: simulators and exact error models", ("navlib.sensors",)),
    ("methods", "Methods: estimators, networks, optimisers, filters", ("navlib.methods",)),
    ("workbench", "Workbench: find the missing physical effect", ("navlib.workbench",)),
    ("studies", "Studies: one module per source", ("navlib.studies",)),
    ("data", "Data: loaders with validation", ("navlib.data", "navlib.paths")),
    ("cli", "Command line", ("navlib.cli", "navlib.commands")),
    (
        "foundations",
        "Shared tools: claims, verdicts, engine, seeds, figure style",
        (
            "navlib.claims",
            "navlib.verdicts",
            "navlib.formatting",
            "navlib.plotstyle",
            "navlib.engine",
            "navlib.seeding",
            "navlib.angles",
            "navlib.errors",
            "navlib._optional",
        ),
    ),
    ("internals", "The book's tooling (package navbook, not in navlib's wheel)", ("navbook",)),
)


def api_layer(module: str) -> str:
    """The :data:`API_LAYERS` page of a module (the longest matching prefix); ``"foundations"`` for a
    module no layer names."""
    best, length = "foundations", -1
    for name, _, prefixes in API_LAYERS:
        for pre in prefixes:
            if (module == pre or module.startswith(pre + ".")) and len(pre) > length:
                best, length = name, len(pre)
    return best


def module_summary(module: str) -> str:
    """The first sentence of a module's docstring (for the API pages' summary tables)."""
    try:
        doc = importlib.import_module(module).__doc__ or ""
    except ImportError as err:  # an optional extra missing: say so instead of failing the page
        return f"(not importable here: {err})"
    text = re.sub(r"\s+", " ", doc).strip()
    first = text
    for m in re.finditer(r"[.:](?=\s|$)", text):
        word = re.search(r"(\S+)$", text[: m.start()])
        if (word and word.group(1).lower() in _NOT_SENTENCE_ENDS) or text[
            m.start() - 1 : m.start()
        ] == ".":
            continue  # "Yu et al. 2012", "eq. 3", "e.g. a sensor"
        first = text[: m.start()] + "."
        break
    first = re.sub(r":\w+:`~?([^`]+)`", r"``\1``", first).replace("*", "")  # roles -> literals
    first = first.replace("``", "`")  # RST -> MyST literal
    if len(first) > 200:  # cut at a word, closing an open literal
        first = first[:200].rsplit(" ", 1)[0]
        first += ("`" if first.count("`") % 2 else "") + " ..."
    elif first.count("`") % 2:  # the sentence ended inside a literal
        first = first[:-1] + "`."
    return first


_NOT_SENTENCE_ENDS = {"al", "eq", "e.g", "i.e", "fig", "figs", "vs", "cf", "no", "sec"}


def api_pages(modules: list[str]) -> dict[str, str]:
    """The API reference as pages (MyST markdown), keyed by file stem: ``api_modules`` (the overview: one
    row per layer with its modules) and ``api_<layer>`` per layer of :data:`API_LAYERS` (a summary table
    of its modules, then one ``automodule`` section per module, :func:`api_markdown`)."""
    groups = {name: [m for m in modules if api_layer(m) == name] for name, _, _ in API_LAYERS}
    overview = ["| layer | modules |", "|---|---|"]
    pages = {}
    for name, title, _ in API_LAYERS:
        mods = groups[name]
        if not mods:  # the table of contents lists every layer's page
            pages[f"api_{name}"] = f"# {title}\n\nNo module of navlib belongs here yet.\n"
            continue
        overview.append(
            f"| {{doc}}`{title} </_generated/api_{name}>` | "
            + ", ".join(f"`{m}`" for m in mods)
            + " |"
        )
        table = ["| module | what it holds |", "|---|---|"]
        table += [f"| {{py:mod}}`{m}` | {_md_cell(module_summary(m))} |" for m in mods]
        pages[f"api_{name}"] = "\n".join([f"# {title}", ""] + table + ["", api_markdown(mods)])
    pages["api_modules"] = "\n".join(overview) + "\n"
    return pages


def write_api(out: Path) -> int:
    """Write the API overview to ``out`` and one page per layer beside it (``api_<layer>.md``)."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    mods = navlib_modules()
    pages = api_pages(mods)
    for stem, text in pages.items():
        (out if stem == "api_modules" else out.with_name(f"{stem}.md")).write_text(
            text, encoding="utf-8"
        )
    print(f"api-modules: {len(mods)} modules on {len(pages) - 1} pages -> {out.parent}")
    return 0

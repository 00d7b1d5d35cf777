"""The keywords' reference text for hover, taken from docs/language.md.

The docs are not installed with the package, so the text hover shows is
cut out of docs/language.md once and shipped as ``reference.json`` beside
this module; ``python -m liganimate.lsp.reference docs/language.md``
writes it again, and tests/lsp/test_reference.py fails when the shipped
table is not what the current document gives.

Each keyword gets the section of the reference that defines it: the first
section whose heading names it, else the first whose grammar (its fenced
blocks) uses it, else the first that writes it in backquotes. A built-in
function gets its row of the functions' table. The text is the section's
heading, its first grammar block (else its first example) and its first paragraph.
"""

from __future__ import annotations

import functools
import json
import re
import sys
from dataclasses import dataclass
from importlib import resources

_HEADING = re.compile(r"^(#{2,4}) (.+)$", re.MULTILINE)
_FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
#: Where the reference part of the document ends: the notes after it repeat the same words.
_LAST = "5. How a program runs"
_MAX_CHARS = 1200
_RULE = re.compile(r"^\s*[a-z_]+\s*(=|:)\s", re.MULTILINE)


@dataclass(frozen=True)
class Section:
    """One headed part of the document."""

    title: str
    anchor: str
    body: str


def _anchor(title: str) -> str:
    """GitHub's anchor for a heading."""
    slug = re.sub(r"[^\w\- ]", "", title.lower()).strip()
    return slug.replace(" ", "-")


def sections(doc: str) -> list:
    """The document's sections up to the end of the reference part, in order."""
    heads = list(_HEADING.finditer(doc))
    out = []
    for i, m in enumerate(heads):
        title = m.group(2).strip()
        if title.startswith(_LAST):
            break
        end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
        out.append(Section(title, _anchor(title), doc[m.end() : end].strip("\n")))
    return out


def _words(text: str) -> set:
    return set(re.findall(r"(?<![A-Za-z0-9_$])[A-Z][A-Z0-9_]*(?![A-Za-z0-9_])", text))


def _grammar_blocks(body: str) -> list:
    """The fenced blocks of ``body`` that hold grammar rules (``rule = ...`` or ``rule : ...``), not examples."""
    return [m.group(1) for m in _FENCE.finditer(body) if _RULE.search(m.group(1))]


def _first_paragraph(body: str) -> str:
    prose = _FENCE.sub("", body)
    for para in re.split(r"\n\s*\n", prose):
        para = para.strip()
        if para and not para.startswith("|") and not para.startswith("#"):
            return " ".join(para.split())
    return ""


def _entry(section: Section) -> str:
    parts = [f"**{section.title}** (docs/language.md#{section.anchor})"]
    fences = _grammar_blocks(section.body) or [m.group(1) for m in _FENCE.finditer(section.body)]
    if fences:
        parts.append("```\n" + fences[0].rstrip() + "\n```")
    para = _first_paragraph(section.body)
    if para:
        parts.append(para)
    text = "\n\n".join(parts)
    return text if len(text) <= _MAX_CHARS else text[: _MAX_CHARS - 1].rstrip() + "…"


def _function_rows(doc_sections: list) -> dict:
    """NAME -> its row of the built-in functions' table, as Markdown."""
    table = next((s for s in doc_sections if s.title == "Built-in functions"), None)
    out: dict = {}
    if table is None:
        return out
    for line in table.body.splitlines():
        if not line.startswith("| `"):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        for name in re.findall(r"`([A-Z][A-Z0-9]*)\(", cells[0]):
            out.setdefault(
                name,
                f"**{name}**: built-in function (docs/language.md#{table.anchor})\n\n"
                f"{cells[0]}: argument {cells[1]}; result {cells[2]}",
            )
    return out


def build(doc: str, keywords: list) -> dict:
    """``{KEYWORD: Markdown}`` for every keyword of ``keywords`` the document describes.

    Parameters
    ----------
    doc : str
        The text of docs/language.md.
    keywords : list of str
        The upper-case words to look up (the grammar's keywords).
    """
    found = sections(doc)
    heads = [(s, _words(s.title)) for s in found]
    grammars = [(s, _words("\n".join(_grammar_blocks(s.body)))) for s in found]
    quoted = [(s, set(re.findall(r"`([A-Z][A-Z0-9_]*)", s.body))) for s in found]
    out = _function_rows(found)
    for word in sorted(set(keywords)):
        if word in out:
            continue
        for candidates in (heads, grammars, quoted):
            section = next((s for s, words in candidates if word in words), None)
            if section is not None:
                out[word] = _entry(section)
                break
    # Spelling variants (docs/language.md, section 1) share their word's entry.
    for word in sorted(set(keywords) - set(out)):
        for variant in (word + "S", word[:-1], word.replace("ISE", "IZE"), word.replace("COLOR", "COLOUR")):
            if variant in out:
                out[word] = out[variant]
                break
    return dict(sorted(out.items()))


def grammar_keywords() -> list:
    """The grammar's keywords, the built-in functions, the interpolation methods and the solvers: what hover explains."""
    from liganimate.lang.parser import grammar
    from liganimate.lang.vocabulary import FUNCTIONS
    from liganimate.runtime.ik.solvers import SOLVER_KEYWORDS
    from liganimate.runtime.motion.interpolation import names

    from .completion import keyword_terminals

    words = set(keyword_terminals(grammar().terminals).keys())
    return sorted(words | set(FUNCTIONS) | set(names()) | set(SOLVER_KEYWORDS))


@functools.lru_cache(maxsize=1)
def table() -> dict:
    """The shipped ``{KEYWORD: Markdown}`` table."""
    data = resources.files(__package__).joinpath("reference.json").read_text(encoding="utf-8")
    return json.loads(data)


def dumps(entries: dict) -> str:
    """The table as ``reference.json`` holds it."""
    return json.dumps(entries, indent=1, ensure_ascii=False, sort_keys=True) + "\n"


def main(argv: list | None = None) -> int:
    """``python -m liganimate.lsp.reference docs/language.md [OUT]``: write the table (default: beside this module)."""
    from pathlib import Path

    args = sys.argv[1:] if argv is None else argv
    if not args:
        sys.stderr.write("usage: python -m liganimate.lsp.reference docs/language.md [reference.json]\n")
        return 2
    doc = Path(args[0]).read_text(encoding="utf-8")
    out = Path(args[1]) if len(args) > 1 else Path(__file__).with_name("reference.json")
    from liganimate.runtime.files import AtomicWriter

    with AtomicWriter(str(out)) as fh:
        fh.write(dumps(build(doc, grammar_keywords())).encode("utf-8"))
    return 0


if __name__ == "__main__":
    sys.exit(main())


__all__ = ["Section", "build", "dumps", "grammar_keywords", "sections", "table"]

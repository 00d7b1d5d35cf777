"""``liganimate lsp``: the language server, over stdio, built on pygls.

This module only wires the protocol to the modules that do the work: the
analysis of a change runs in one worker thread (:mod:`.analysis`), the
index and values built after its diagnostics are published in another
(the two never run at once: they share the compiler's lock), and
every request is answered at once from the latest analysis, the last one
whose text parsed, and the tolerant scan of the text as it is now, never
waiting for an analysis to finish. A change is analysed at once; changes
that arrive while an analysis runs are taken together by the next one, and
only the diagnostics of an analysis whose text is still current are
published.
"""

from __future__ import annotations

import asyncio
import logging
import sys
from concurrent.futures import ThreadPoolExecutor

from lsprotocol import types as lsp
from pygls.exceptions import JsonRpcException
from pygls.lsp.server import LanguageServer
from pygls.uris import from_fs_path, to_fs_path

from liganimate import __version__
from liganimate.lang.parser import BUILTIN_PRIMITIVES
from liganimate.lang.parser import reparser as reparser_for_document
from liganimate.lang.source import prepare

from . import completion as C
from . import hover as H
from . import navigation as N
from . import outline, scan
from .analysis import COMPILER_LOCK, Analysis, analyse, complete
from .lookup import target
from .text import Text

_REQUEST_FAILED = -32803  # the protocol's RequestFailed

log = logging.getLogger(__name__)


class LigServer(LanguageServer):
    """The server's state: the documents' analyses, and the worker that makes them."""

    def __init__(self) -> None:
        # Whole texts, not edits: pygls applies an edit by lines it cuts with str.splitlines, which also
        # breaks at a form feed (LIG text may hold one; editors and LIG do not break lines there), so an
        # edit after a form feed would land on the wrong line.
        super().__init__("liganimate", __version__, text_document_sync_kind=lsp.TextDocumentSyncKind.Full)
        self.latest: dict = {}  # uri -> Analysis of some version (maybe not the newest)
        self.good: dict = {}  # uri -> the last Analysis whose text parsed
        self.pending: dict = {}  # uri -> the asyncio task that will analyse it
        self.reparsers: dict = {}  # uri -> its Reparser (lang/incremental.py), used only by the worker
        self.whole_parse = False  # True: no Reparser, every change parses the whole text (liganimate lsp --whole-parse)
        self.worker = _named_worker("lig-analysis")
        self.indexer = _named_worker("lig-index")

    def encoding(self) -> str:
        """The position encoding agreed with the client."""
        return str(self.workspace.position_encoding or lsp.PositionEncodingKind.Utf16)

    def source(self, uri: str) -> str:
        """The document's text as the client last sent it."""
        return self.workspace.get_text_document(uri).source

    def text(self, uri: str) -> Text:
        """The document's text now, with its positions."""
        return Text(self.source(uri), self.encoding())


def _named_worker(name: str) -> ThreadPoolExecutor:
    """A one-thread pool whose thread the system knows by ``name`` (``top -H``; benchmarks/lsp.py reads it)."""
    return ThreadPoolExecutor(max_workers=1, thread_name_prefix=name, initializer=_name_thread, initargs=(name,))


def _name_thread(name: str) -> None:
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            ctypes.CDLL(None).prctl(15, name.encode("ascii")[:15], 0, 0, 0)  # PR_SET_NAME
        except (OSError, AttributeError):
            pass  # the name is for people watching the process; the server works without it


server = LigServer()


def _path(uri: str) -> str | None:
    return to_fs_path(uri) if uri.startswith("file:") else None


def _schedule(ls: LigServer, uri: str) -> None:
    """Analyse ``uri``'s text now, or, if an analysis of it is running, once more when it ends."""
    task = ls.pending.get(uri)
    if task is None or task.done():
        ls.pending[uri] = asyncio.ensure_future(_analyse_until_current(ls, uri))


async def _analyse_until_current(ls: LigServer, uri: str) -> None:
    """Analyse the document until an analysis ends on the text it started from; publish that one's diagnostics.

    A change that arrives while an analysis runs is not analysed on its
    own: the next round takes the text as it is then, so a burst of
    keystrokes costs one analysis more than the one running, and a single
    change is analysed at once, with no pause. The diagnostics go out as
    soon as they are known, before the index and the values that requests
    use are built (until then requests are answered from the last analysis),
    and those are built only for a text that is still current.
    """
    loop = asyncio.get_running_loop()
    await asyncio.sleep(0)  # the change's own handler first
    reparser = None if ls.whole_parse else ls.reparsers.setdefault(uri, reparser_for_document())
    while uri in ls.workspace.text_documents:
        doc = ls.workspace.get_text_document(uri)
        version, source = doc.version, doc.source
        result = await loop.run_in_executor(
            ls.worker, _analyse_safely, source, _path(uri), version, ls.encoding(), reparser
        )
        if uri not in ls.workspace.text_documents:
            return  # closed meanwhile
        if ls.workspace.get_text_document(uri).version != version:
            continue  # changed meanwhile: the newer text next, at once
        ls.text_document_publish_diagnostics(
            lsp.PublishDiagnosticsParams(uri=uri, version=version, diagnostics=_diagnostics(result))
        )
        result = await loop.run_in_executor(ls.indexer, _complete_safely, result)
        if uri not in ls.workspace.text_documents:
            return
        ls.latest[uri] = result
        if result.parsed:
            ls.good[uri] = result
        if ls.workspace.get_text_document(uri).version == version:
            return  # else a change came meanwhile, which _schedule left to this task


def _analyse_safely(source: str, path: str | None, version, encoding: str, reparser) -> Analysis:
    try:
        return analyse(source, path, version, encoding, whole=False, reparser=reparser)
    except Exception:  # noqa: BLE001 - a bug must cost one analysis, not the editor's server
        log.exception("the analysis failed")
        if reparser is not None:
            reparser.forget()  # the next analysis parses the whole text
        return Analysis(Text(source, encoding), version, path, [])


def _complete_safely(a: Analysis) -> Analysis:
    try:
        return complete(a)
    except Exception:  # noqa: BLE001 - as in _analyse_safely
        log.exception("the analysis failed")
        return Analysis(a.text, a.version, a.path, a.diagnostics)


_SEVERITY = {"error": lsp.DiagnosticSeverity.Error, "warning": lsp.DiagnosticSeverity.Warning}


def _diagnostics(a: Analysis) -> list:
    """The analysis' diagnostics as the protocol's; those of other files (a library's) go with the next one here."""
    own = a.path or "<untitled>"
    out: list = []
    related: list = []
    for d in a.diagnostics:
        if d.filename != own:
            related.append(
                lsp.DiagnosticRelatedInformation(
                    location=lsp.Location(uri=_uri_of(d.filename), range=_plain_range(d.pos)),
                    message=d.message + (f" (hint: {d.hint})" if d.hint else ""),
                )
            )
            continue
        message = d.message
        for note in d.notes:
            message += f"\nnote: {note}"
        if d.hint:
            message += f"\nhint: {d.hint}"
        out.append(
            lsp.Diagnostic(
                range=a.text.lig_range(d.pos.line, d.pos.column, d.pos.end_line, d.pos.end_column),
                message=message,
                severity=_SEVERITY.get(d.severity, lsp.DiagnosticSeverity.Information),
                source="liganimate",
                related_information=related or None,
            )
        )
        related = []
    return out


def _uri_of(filename: str) -> str:
    return from_fs_path(filename) or filename


def _plain_range(pos) -> lsp.Range:
    start = lsp.Position(line=max(pos.line - 1, 0), character=max(pos.column - 1, 0))
    end = lsp.Position(line=max(pos.end_line - 1, 0), character=max(pos.end_column - 1, 0))
    return lsp.Range(start=start, end=end)


# ------------------------------------------------------------------ documents


@server.feature(lsp.TEXT_DOCUMENT_DID_OPEN)
async def did_open(ls: LigServer, params: lsp.DidOpenTextDocumentParams) -> None:
    """Analyse a document when it opens."""
    _schedule(ls, params.text_document.uri)


@server.feature(lsp.TEXT_DOCUMENT_DID_CHANGE)
async def did_change(ls: LigServer, params: lsp.DidChangeTextDocumentParams) -> None:
    """Analyse a document after it changes."""
    _schedule(ls, params.text_document.uri)


@server.feature(lsp.TEXT_DOCUMENT_DID_SAVE)
async def did_save(ls: LigServer, params: lsp.DidSaveTextDocumentParams) -> None:
    """Analyse every open document again on save: the saved file may be a library the others LOAD."""
    for uri in list(ls.workspace.text_documents):
        _schedule(ls, uri)


@server.feature(lsp.TEXT_DOCUMENT_DID_CLOSE)
async def did_close(ls: LigServer, params: lsp.DidCloseTextDocumentParams) -> None:
    """Forget a closed document and clear its diagnostics."""
    uri = params.text_document.uri
    task = ls.pending.pop(uri, None)
    if task is not None:
        task.cancel()
    ls.latest.pop(uri, None)
    ls.good.pop(uri, None)
    ls.reparsers.pop(uri, None)
    ls.text_document_publish_diagnostics(lsp.PublishDiagnosticsParams(uri=uri, diagnostics=[]))


# ------------------------------------------------------------------ requests


def _state(ls: LigServer, uri: str) -> tuple:
    return ls.text(uri), ls.latest.get(uri), ls.good.get(uri)


@server.feature(lsp.TEXT_DOCUMENT_HOVER)
def on_hover(ls: LigServer, params: lsp.HoverParams) -> lsp.Hover | None:
    """A keyword's reference text, or a name's type, value and origin."""
    text, latest, good = _state(ls, params.text_document.uri)
    offset = text.offset(params.position)
    found = H.hover(text.source, offset, target(text.source, offset, latest, good), latest, good)
    if found is None:
        return None
    markdown, start, end = found
    return lsp.Hover(
        contents=lsp.MarkupContent(kind=lsp.MarkupKind.Markdown, value=markdown), range=text.range(start, end)
    )


_KINDS = {
    "keyword": lsp.CompletionItemKind.Keyword,
    "variable": lsp.CompletionItemKind.Variable,
    "primitive": lsp.CompletionItemKind.Function,
    "library": lsp.CompletionItemKind.Module,
    "file": lsp.CompletionItemKind.File,
    "method": lsp.CompletionItemKind.EnumMember,
    "clause": lsp.CompletionItemKind.Property,
}


@server.feature(lsp.TEXT_DOCUMENT_COMPLETION, lsp.CompletionOptions(trigger_characters=["<", "'", ",", " "]))
def on_completion(ls: LigServer, params: lsp.CompletionParams) -> lsp.CompletionList:
    """Keywords the grammar takes at the cursor, names in scope, libraries, methods."""
    uri = params.text_document.uri
    text, latest, good = _state(ls, uri)
    items = _completions(text.source, text.offset(params.position), good, _path(uri))
    return lsp.CompletionList(
        is_incomplete=False,
        items=[
            lsp.CompletionItem(label=i.label, kind=_KINDS.get(i.kind), detail=i.detail or None, sort_text=_sort(i))
            for i in items
        ],
    )


def _sort(item: C.Item) -> str:
    order = {"variable": "1", "primitive": "2", "clause": "0", "method": "0", "library": "0", "file": "1"}
    return order.get(item.kind, "3") + item.label


def _completions(source: str, offset: int, good: Analysis | None, path: str | None) -> list:
    start = offset
    while start > 0 and (source[start - 1].isalnum() or source[start - 1] == "_"):
        start -= 1
    context = C.load_context(source, offset)
    if context is not None:
        return _load_items(context, path)
    if _in_comment_or_string(source, start):
        return []
    word = C.word_context(source, offset)
    if word == "method":
        return [C.Item(m, "method", "interpolation method") for m in C.methods()]
    if word == "solver":
        return [C.Item(s, "method", "REACH solver") for s in C.solvers()]
    loaded_prims = {n for n, info in (good.libraries if good else {}).items() if info.offered.get(n) == "PRIMITIVE"}
    primitives = frozenset(BUILTIN_PRIMITIVES | prepare(source, "").primitive_names() | loaded_prims)
    terminals = C.terminals_at(source, start, primitives)
    keywords = C.keywords_for(terminals)
    narrowed = C.modifier_words(source[max(0, start - 400) : start], _type_before(source, start, good))
    if narrowed is not None:
        words, value = narrowed
        keywords = [k for k in keywords if k in words]
        if not value:
            terminals = terminals - {"NAME", "PRIM_NAME"}
    items = [C.Item(k, "keyword") for k in keywords]
    if "NAME" in terminals and good is not None and good.index is not None:
        scope = good.index.scope_at(min(start, len(good.text.source)))
        types = good.checked.main.types if good.checked is not None else {}
        names = set(good.index.names(scope)) | set(good.libraries)
        items += [C.Item(n, "variable", types.get(n, "")) for n in sorted(names) if n not in primitives]
    if "PRIM_NAME" in terminals:
        items += [C.Item(p, "primitive", "PRIMITIVE") for p in sorted(primitives)]
    if "CLAUSE_NAME" in terminals:
        items += _clause_items(source, start, primitives, good)
    return items


def _type_of_name(good: Analysis | None, name: str) -> str | None:
    if good is None:
        return None
    if good.checked is not None and name in good.checked.main.types:
        return good.checked.main.types[name]
    info = good.libraries.get(name)
    return info.offered.get(name) if info is not None else None


def _type_before(source: str, start: int, good: Analysis | None) -> str | None:
    """The type of the name a ``<`` list before ``start`` modifies, if the last good analysis knows it."""
    m = C._MODIFIER_TARGET.search(source[max(0, start - 400) : start])
    return _type_of_name(good, m.group(1).upper()) if m is not None else None


def _in_comment_or_string(source: str, offset: int) -> bool:
    line_start = source.rfind("\n", 0, offset) + 1
    before = source[:line_start]
    begin = 0 if before.rfind("{") > before.rfind("}") else line_start
    tok = scan.at(scan.tokens(source[begin:offset]), offset - begin)
    if tok is not None and tok.kind in ("comment", "string"):
        closed = tok.value.endswith("}") if tok.kind == "comment" else len(tok.value) > 1 and tok.value.endswith("'")
        return not (closed and tok.end + begin == offset)
    return False


def _clause_items(source: str, start: int, primitives: frozenset, good: Analysis | None) -> list:
    """The clauses a primitive call may take next: in pattern order, up to the next one it must have."""
    toks = scan.tokens(source[max(0, start - 2000) : start])
    name = C.primitive_words(source, start, toks, primitives)
    sig = H._signature(good, name) if name is not None else None
    if sig is None:
        return []
    words = [t.value for t in toks if t.kind == "word"]
    after = words[len(words) - 1 - words[::-1].index(name) + 1 :] if name in words else []
    keywords = [s.keyword for s in sig.slots]
    written = [keywords.index(w) for w in after if w in keywords]
    out = []
    for slot in sig.slots[(max(written) + 1 if written else 0) :]:
        out.append(C.Item(slot.keyword, "clause", f"{name} {slot.keyword} {slot.param.lower()}"))
        if slot.group is None:
            break  # a clause the call must have comes next
    return out


def _load_items(context: tuple, path: str | None) -> list:
    import os

    from . import libraries

    kind, value = context
    if kind == "library":
        return C.library_files(os.path.dirname(path) if path else None)
    with COMPILER_LOCK:  # opening a library compiles it: not beside an analysis
        info = libraries.open_library(value, path)
    if info is None:
        return []
    return [C.Item(n, "variable", info.offered[n] + " " + info.descriptions.get(n, "")) for n in sorted(info.offered)]


def _location(ls: LigServer, uri: str, text: Text, place: N.Place) -> lsp.Location:
    if place.path is None:
        return lsp.Location(uri=uri, range=text.range(place.start, place.end))
    from . import libraries

    info = next((i for _, _, i in libraries._cache.values() if i is not None and i.path == place.path), None)
    lib_text = Text(info.text.source, ls.encoding()) if info is not None else Text("")
    return lsp.Location(uri=_uri_of(place.path), range=lib_text.range(place.start, place.end))


@server.feature(lsp.TEXT_DOCUMENT_DEFINITION)
def on_definition(ls: LigServer, params: lsp.DefinitionParams) -> lsp.Location | None:
    """Where the name under the cursor is defined, in this file or in the library that brings it."""
    uri = params.text_document.uri
    text, latest, good = _state(ls, uri)
    where = target(text.source, text.offset(params.position), latest, good)
    if where is None:
        return None
    place = N.definition(where, text.source, latest, good)
    return None if place is None else _location(ls, uri, text, place)


@server.feature(lsp.TEXT_DOCUMENT_REFERENCES)
def on_references(ls: LigServer, params: lsp.ReferenceParams) -> list:
    """Every occurrence of the name under the cursor in the document."""
    uri = params.text_document.uri
    text, latest, good = _state(ls, uri)
    where = target(text.source, text.offset(params.position), latest, good)
    if where is None:
        return []
    places = N.references(where, text.source, latest, params.context.include_declaration)
    return [_location(ls, uri, text, p) for p in places]


@server.feature(lsp.TEXT_DOCUMENT_PREPARE_RENAME)
def on_prepare_rename(ls: LigServer, params: lsp.PrepareRenameParams) -> lsp.Range:
    """The name a rename here would change, or an error saying why there is none."""
    text, latest, good = _state(ls, params.text_document.uri)
    try:
        where = N.prepare(target(text.source, text.offset(params.position), latest, good), latest)
    except N.RenameRefused as exc:
        raise JsonRpcException(str(exc), _REQUEST_FAILED) from None
    return text.range(where.start, where.end)


@server.feature(lsp.TEXT_DOCUMENT_RENAME)
def on_rename(ls: LigServer, params: lsp.RenameParams) -> lsp.WorkspaceEdit:
    """Rename a variable, model, motion or primitive across the file."""
    uri = params.text_document.uri
    text, latest, good = _state(ls, uri)
    where = target(text.source, text.offset(params.position), latest, good)
    try:
        if where is None or latest is None:
            raise N.RenameRefused("there is no name here to rename")
        places = N.rename(where, params.new_name, latest)
    except N.RenameRefused as exc:
        raise JsonRpcException(str(exc), _REQUEST_FAILED) from None
    new = params.new_name.strip().upper()
    edits = [lsp.TextEdit(range=text.range(p.start, p.end), new_text=new) for p in places]
    return lsp.WorkspaceEdit(changes={uri: edits})


_SYMBOL_KINDS = {
    "model": lsp.SymbolKind.Class,
    "motion": lsp.SymbolKind.Event,
    "scene": lsp.SymbolKind.Module,
    "primitive": lsp.SymbolKind.Function,
    "integer": lsp.SymbolKind.Number,
    "real": lsp.SymbolKind.Number,
    "vector": lsp.SymbolKind.Array,
    "graphical": lsp.SymbolKind.Object,
}


@server.feature(lsp.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def on_symbols(ls: LigServer, params: lsp.DocumentSymbolParams) -> list:
    """The models, motions, scenes, primitives and variables of the document."""
    uri = params.text_document.uri
    text, latest, good = _state(ls, uri)
    a = latest if latest is not None and latest.parsed else good
    if a is None:
        return []
    shown = Text(a.text.source, ls.encoding())
    return [
        lsp.DocumentSymbol(
            name=s.name,
            kind=_SYMBOL_KINDS.get(s.kind, lsp.SymbolKind.Variable),
            detail=s.detail or None,
            range=shown.range(s.start, s.end),
            selection_range=shown.range(s.name_start, s.name_end),
        )
        for s in outline.symbols(a)
    ]


@server.feature(lsp.TEXT_DOCUMENT_FOLDING_RANGE)
def on_folding(ls: LigServer, params: lsp.FoldingRangeParams) -> list:
    """The blocks and long comments of the document, as it is now."""
    source = ls.source(params.text_document.uri)
    return [
        lsp.FoldingRange(
            start_line=f.start_line,
            end_line=f.end_line,
            kind=lsp.FoldingRangeKind.Comment if f.comment else lsp.FoldingRangeKind.Region,
        )
        for f in outline.folds(source)
    ]


def main(*, whole_parse: bool = False) -> int:
    """Serve over stdin and stdout until the client says exit; ``whole_parse``: see :class:`LigServer`."""
    server.whole_parse = whole_parse
    server.start_io()
    return 0


__all__ = ["LigServer", "main", "server"]

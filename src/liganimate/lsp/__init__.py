"""The language server (``liganimate lsp``): diagnostics, hover, completion and navigation for LIG programs.

A tool above the compiler, like the command line: it reads programs with
the front end (``lang``) and the checker (``compiler``), and never runs
them. One module a job:

* :mod:`.text`: positions (offsets, LIG lines and columns, the client's units);
* :mod:`.scan`: the tolerant scan that works on broken text (words, blocks);
* :mod:`.analysis`: one version of a document, analysed (diagnostics, tree);
* :mod:`.index`: where each name is defined and used;
* :mod:`.statics`: what the text fixes of values (models' joints, motions' lengths);
* :mod:`.libraries`: the LOADed files, read the same way;
* :mod:`.reference`: the keywords' text from docs/language.md (``reference.json``);
* :mod:`.completion`, :mod:`.hover`, :mod:`.navigation`, :mod:`.outline`: the features;
* :mod:`.server`: the protocol (pygls), wiring the above.
"""

from __future__ import annotations


def main(*, whole_parse: bool = False) -> int:
    """Run the server over stdio (``liganimate lsp``); ``whole_parse`` parses the whole text after every change."""
    from .server import main as serve

    return serve(whole_parse=whole_parse)


__all__ = ["main"]

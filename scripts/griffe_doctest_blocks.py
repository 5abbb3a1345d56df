"""A griffe extension for the docs site (mkdocs.yml): show docstring examples as code.

The docstrings write their examples as bare doctest paragraphs (``>>>`` lines and their output,
up to a blank line), which the test suite runs. Markdown would read them as quotes, so each
such paragraph outside a fenced block is wrapped in a ``pycon`` fence before the docstring is
parsed.
"""

from __future__ import annotations

from typing import Any

import griffe


def fence_doctests(text: str) -> str:
    """Wrap every doctest paragraph of ``text`` in a ```` ```pycon ```` fence.

    >>> fence_doctests("Add.\\n\\n>>> 1 + 1\\n2\\n\\nDone.").split("\\n")
    ['Add.', '', '```pycon', '>>> 1 + 1', '2', '```', '', 'Done.']
    """
    out: list[str] = []
    in_fence = in_doctest = False
    indent = ""
    for line in text.split("\n"):
        stripped = line.strip()
        if in_doctest and not stripped:
            out.append(f"{indent}```")
            in_doctest = False
        elif stripped.startswith("```"):
            in_fence = not in_fence
        elif not in_fence and not in_doctest and stripped.startswith(">>>"):
            indent = line[: len(line) - len(line.lstrip())]
            out.append(f"{indent}```pycon")
            in_doctest = True
        out.append(line)
    if in_doctest:
        out.append(f"{indent}```")
    return "\n".join(out)


class DoctestBlocks(griffe.Extension):
    """Fence the doctest paragraphs of every docstring."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None and ">>>" in obj.docstring.value:
            obj.docstring.value = fence_doctests(obj.docstring.value)

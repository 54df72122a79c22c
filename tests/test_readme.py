"""The README's Python snippets run as written and print what the README shows.

Every ```` ```pycon ```` block of README.md is one part of a single doctest (the
blocks share their names, as a reader typing them in order would), run in a
temporary directory. Plain ```` ```python ```` blocks are not allowed: a snippet
either shows its true output or is not in the README.
"""

from __future__ import annotations

import doctest
import re
import warnings
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)


def _blocks(kind: str) -> list[str]:
    return [body for lang, body in FENCE.findall(README.read_text()) if lang == kind]


def test_readme_has_no_untested_python_blocks():
    assert _blocks("python") == [], "README python blocks must be pycon (tested) blocks"
    assert len(_blocks("pycon")) >= 5


def test_readme_snippets_print_what_they_show(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = "\n".join(_blocks("pycon"))
    parser = doctest.DocTestParser()
    test = parser.get_doctest(text, {}, "README", str(README), 0)
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    runner = doctest.DocTestRunner(optionflags=flags)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.attempted > 20
    assert result.failed == 0, f"{result.failed} README example(s) failed (see output above)"

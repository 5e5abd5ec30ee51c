"""The only links a report emits: http(s) URLs and relative file paths.

A result document is data from a file, which may have been edited: a `recording` of
`javascript:alert(1)` or `data:text/html,...` must not become a live link.  Values with
any other URL scheme are refused when the document is read (`link_problem`,
harness.report.schema); a file path becomes a relative, percent-encoded href
(`file_href`), which can name no scheme."""

from __future__ import annotations

import os
import re
from pathlib import Path
from urllib.parse import quote

WEB = ("http", "https")
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*):")


def url_scheme(value: str) -> str | None:
    """The URL scheme `value` starts with (lower case), None for a plain path."""
    m = _SCHEME.match(value.strip())
    return m.group(1).lower() if m else None


def link_problem(value: str) -> str:
    """Why `value` may not be linked ('' when it may): a scheme other than http(s), or
    control characters."""
    scheme = url_scheme(value)
    if scheme is not None and scheme not in WEB:
        return f"only http(s) URLs or file paths can be linked, not a {scheme}: URL"
    if any(ord(ch) < 32 or ord(ch) == 127 for ch in value):
        return "a link with control characters"
    return ""


def file_href(path: str, out_dir: Path) -> str:
    """The href of `path` from the report's folder: the URL itself for http(s), else the
    path relative to `out_dir`, percent-encoded (':' too, so no scheme can appear)."""
    if link_problem(path):
        raise ValueError(link_problem(path))
    if url_scheme(path) in WEB:
        return path.strip()
    rel = os.path.relpath(Path(path).resolve(), out_dir.resolve())
    return quote(rel.replace(os.sep, "/"), safe="/._-~")

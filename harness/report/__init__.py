"""`harness report`: one self-contained HTML file from result documents.

Inputs (any number, in the order given):

- a JSON document of `harness compare --json`, `bench --json` / `--out`, `fidelity
  --json` / `--out`, `stress --json`, `sweep exponent --json` or `restitution --json` /
  `--out`;
- a sweep directory: ROOT/<engine> (holding manifest.json and parts/), or a study
  directory ROOT holding several of them (one section per engine).

The kind of a document is recognised from its fields (`detect_kind`).  Each gets a
section: its tables, its verdicts, its figures and its provenance (the command that made
it, when, on what machine: harness.provenance); the versions once, in a table at the end
(a section lists only the versions that differ from it).

How the report finds the plots: it does not.  Every figure is redrawn from the data in
the document (work-precision from the bench rows, α* and matched fractions from the
fidelity rows, the exponent map from the sweep's per-point means), by the same functions
the commands use, and embedded as a PNG data URI.  The file loads nothing from anywhere:
no scripts, no external styles, fonts or images; it opens offline in any browser and
can be mailed or archived alone.  The one link out is to a compare run's `.rrd`
recording (relative to the report's folder), which the browser cannot show anyway; only
relative file paths and http(s) URLs are ever linked (links.py).

Every JSON input is checked against its kind's schema (schema.py) before any HTML is
built: a missing or mistyped field is one line naming it (exit 2).  Every string taken
from an input is HTML-escaped (html.esc).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from reference.scene import input_file_problem
from reference.scene import show_path as show

from .html import details, esc, page
from .restitution import restitution_section
from .schema import SchemaError, check_document
from .sections import (
    bench_section,
    compare_section,
    fidelity_section,
    provenance_section,
    shared_versions,
    stress_section,
    sweep_command,
    sweep_section,
    versions_table,
)

KINDS = ("compare", "bench", "fidelity", "stress", "sweep", "restitution")


class ReportInputError(ValueError):
    """An input that is not a result document (bad input: exit status 2)."""


@dataclass
class ReportInput:
    path: Path
    kind: str
    doc: dict[str, Any]
    rebuilt_command: str | None = None  # sweep directories: the command from the manifest


def detect_kind(doc: Any) -> str | None:
    """'compare', 'bench', 'fidelity', 'stress' or 'sweep' from a document's fields."""
    if not isinstance(doc, dict):
        return None
    if doc.get("kind") in KINDS:
        return doc["kind"]
    if str(doc.get("command", "")).startswith("sweep"):
        return "sweep"
    if "alpha_star" in doc and "runs" in doc:
        return "fidelity"
    if "truth" in doc and "results" in doc:
        return "bench"
    if "cases" in doc and "thresholds" in doc:
        return "stress"
    engines = doc.get("engines")
    if (
        "reference" in doc
        and isinstance(engines, list)
        and engines
        and "impacts_matched" in engines[0]
    ):
        return "compare"
    return None


def load_inputs(path: str | Path) -> list[ReportInput]:
    """The result documents at `path`: one for a JSON file, one per engine for a sweep
    directory."""
    p = Path(path)
    if p.is_dir():
        return _sweep_directory(p)
    problem = input_file_problem(p)
    if problem:
        raise ReportInputError(f"{show(p)}: {problem}")
    doc = _json_document(p)
    kind = detect_kind(doc)
    if kind is None:
        raise ReportInputError(
            f"{show(p)}: not a result of harness compare, bench, fidelity, stress, sweep or "
            "restitution"
        )
    try:
        check_document(doc, kind)
    except SchemaError as exc:
        raise ReportInputError(f"{show(p)}: not a valid {kind} document: {exc}") from None
    return [ReportInput(p, kind, doc)]


def _json_document(p: Path) -> Any:
    """The JSON document in file `p`, or ReportInputError with the reason: not JSON (a
    decoding error, an integer beyond Python's 4300 digits), nested too deeply for the
    parser (RecursionError), unreadable."""
    try:
        return json.loads(p.read_text(encoding="utf-8-sig"))
    except RecursionError:
        raise ReportInputError(f"{show(p)}: JSON nested too deeply to be a result") from None
    except ValueError as exc:  # JSONDecodeError, UnicodeDecodeError, a huge integer
        reason = " ".join(str(exc).split())[:200]
        raise ReportInputError(f"{show(p)}: not a JSON document ({reason})") from None
    except OSError as exc:
        raise ReportInputError(f"{show(p)}: cannot be read ({exc.strerror})") from None


def _sweep_directory(p: Path) -> list[ReportInput]:
    """A sweep's own directory (manifest.json + parts/) or a study directory of them:
    the same summary `harness sweep exponent` prints, from the stored parts."""
    from ..sweep import summarise
    from ..sweep.store import SweepStore, engines_in, load_results, read_manifest

    own = read_manifest(p)
    found = {own.engine: (p.parent, own)} if own else {}
    if not found:
        found = {e: (p, c) for e, c in engines_in(p).items()}
    if not found:
        raise ReportInputError(f"{p}: a directory without a sweep (no manifest.json)")
    out = []
    for _engine, (root, config) in found.items():
        store = SweepStore(root, config)  # not opened: read only, no lock
        df, duplicates = load_results(store.dir)
        doc = summarise(config, df, store, {}, len(df), 0, duplicates)
        out.append(ReportInput(store.dir, "sweep", doc, sweep_command(config)))
    return out


def _title(item: ReportInput) -> str:
    doc = item.doc
    what = doc.get("scene") or doc.get("engine") or ""
    return f"{item.kind}: {what}" if what else item.kind


def section(item: ReportInput, out_dir: Path, versions: dict[str, str] | None = None) -> str:
    """The HTML section of one input: its kind's tables and figures, then provenance
    (versions only where they differ from the report's table, `versions`)."""
    doc = item.doc
    if item.kind == "compare":
        body = compare_section(doc, out_dir)
    elif item.kind == "bench":
        body = bench_section(doc)
    elif item.kind == "fidelity":
        body = fidelity_section(doc)
    elif item.kind == "stress":
        body = stress_section(doc)
    elif item.kind == "restitution":
        body = restitution_section(doc)
    else:
        body = sweep_section(doc)
    return (
        f"<section><h2>{esc(_title(item))}</h2>"
        f"<p class=muted>from <code>{esc(item.path)}</code></p>\n{body}\n"
        f"{provenance_section(doc, item.rebuilt_command, versions)}</section>"
    )


def build_report(items: list[ReportInput], out_path: str | Path, own: dict[str, Any]) -> str:
    """The whole HTML page.  `own` is the report command's provenance (shown last)."""
    out_dir = Path(out_path).resolve().parent
    contents = "".join(f"<li>{esc(_title(i))} <code>{esc(i.path)}</code></li>" for i in items)
    body = [f"<p>Results in this report:</p><ul>{contents}</ul>"]
    versions = shared_versions([i.doc for i in items]) or dict(own.get("versions", {}))
    body += [section(i, out_dir, versions) for i in items]
    body.append("<section><h2>Versions</h2>" + versions_table(versions) + "</section>")
    body.append(
        details(
            "how this report was made",
            f"<pre>{esc(own['command'])}</pre><p class=muted>{esc(own['created'])}, "
            f"{esc(own['host'])}. Figures are redrawn from the inputs' data and embedded; "
            "the page loads nothing from elsewhere.</p>",
        )
    )
    title = "harness report: " + ", ".join(_title(i) for i in items)
    return page(title, "\n".join(body))

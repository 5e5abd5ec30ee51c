"""HTML building blocks of a self-contained report: escaped text, tables, figures as
PNG data URIs, one page with inline CSS.  Nothing here loads anything from elsewhere:
no scripts, no external styles, fonts or images."""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Sequence
from typing import Any

from ..text import num  # noqa: F401 (the cells' text, re-exported)

CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       margin: 2em auto; max-width: 1200px; padding: 0 1em; color: #222; line-height: 1.4; }
h1 { font-size: 1.6em; border-bottom: 2px solid #444; padding-bottom: .2em; }
h2 { font-size: 1.3em; margin-top: 2em; border-bottom: 1px solid #bbb; }
h3 { font-size: 1.1em; margin-top: 1.5em; }
table { border-collapse: collapse; margin: .8em 0; font-size: .85em; }
caption { text-align: left; font-weight: 600; padding: .3em 0; }
th, td { border: 1px solid #ccc; padding: .25em .5em; text-align: right; vertical-align: top;
         white-space: nowrap; }
th { background: #f0f0f0; }
td.l, th.l { text-align: left; }
th.v { writing-mode: vertical-rl; transform: rotate(180deg); white-space: nowrap;
       padding: .4em .15em; font-weight: normal; }
td.pass { background: #d9f2d9; } td.fail { background: #f7d4d4; }
td.skip { background: #eee; color: #777; } td.na { color: #999; }
div.wide { overflow-x: auto; }  /* a wide table scrolls, the page does not */
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: .85em; color: #555; }
code, pre { font-family: ui-monospace, Menlo, Consolas, monospace; font-size: .85em; }
pre { background: #f6f6f6; padding: .6em; overflow-x: auto; white-space: pre-wrap; }
p.verdict { background: #f6f6f6; border-left: 4px solid #888; padding: .3em .6em; }
details { margin: .6em 0; } summary { cursor: pointer; font-weight: 600; }
.muted { color: #666; font-size: .9em; }
"""


def esc(x: Any) -> str:
    return html.escape(str(x), quote=True)


class Cell:
    """A table cell with a CSS class (e.g. pass / fail / skip) and an optional tooltip."""

    def __init__(self, text: Any, cls: str = "", title: str = ""):
        self.text, self.cls, self.title = text, cls, title

    def render(self) -> str:
        attrs = f' class="{esc(self.cls)}"' if self.cls else ""
        attrs += f' title="{esc(self.title)}"' if self.title else ""
        return f"<td{attrs}>{esc(self.text)}</td>"


def table(
    header: Sequence[str],
    rows: Sequence[Sequence[Any]],
    caption: str = "",
    left: int = 1,
    vertical_from: int | None = None,
) -> str:
    """An HTML table; the first `left` columns are left-aligned (names), the rest right
    (numbers).  Cells are plain values (escaped text) or `Cell`s.  Header cells from
    column `vertical_from` on are written vertically (a ladder of many narrow columns
    then fits the page)."""
    out = ['<div class="wide"><table>']
    if caption:
        out.append(f"<caption>{esc(caption)}</caption>")

    def th_class(i: int) -> str:
        if i < left:
            return " class=l"
        return " class=v" if vertical_from is not None and i >= vertical_from else ""

    ths = "".join(f"<th{th_class(i)}>{esc(h)}</th>" for i, h in enumerate(header))
    out.append(f"<thead><tr>{ths}</tr></thead><tbody>")
    for row in rows:
        tds = []
        for i, x in enumerate(row):
            cell = x if isinstance(x, Cell) else Cell(x, "l" if i < left else "")
            if i < left and "l" not in cell.cls.split():
                cell = Cell(cell.text, f"{cell.cls} l".strip(), cell.title)
            tds.append(cell.render())
        out.append(f"<tr>{''.join(tds)}</tr>")
    out.append("</tbody></table></div>")
    return "\n".join(out)


def png_data_uri(fig, dpi: int = 110) -> str:
    """A matplotlib figure as a PNG data URI (the figure is closed)."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def figure(fig, alt: str, caption: str = "") -> str:
    """<figure> with the figure embedded as a PNG data URI."""
    cap = f"<figcaption>{esc(caption)}</figcaption>" if caption else ""
    return f'<figure><img src="{png_data_uri(fig)}" alt="{esc(alt)}">{cap}</figure>'


def paragraph(text: str, cls: str = "") -> str:
    return f"<p{f' class={cls}' if cls else ''}>{esc(text)}</p>"


def details(summary: str, body: str) -> str:
    return f"<details><summary>{esc(summary)}</summary>{body}</details>"


def page(title: str, body: str) -> str:
    """The whole document: inline CSS, no script, nothing loaded from elsewhere."""
    return (
        "<!DOCTYPE html>\n<html lang=en>\n<head>\n<meta charset=utf-8>\n"
        '<meta name=viewport content="width=device-width, initial-scale=1">\n'
        f"<title>{esc(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
        f"<h1>{esc(title)}</h1>\n{body}\n</body>\n</html>\n"
    )

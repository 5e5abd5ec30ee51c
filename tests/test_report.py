"""`harness report`: one self-contained HTML file from the results of compare, bench,
fidelity, stress and sweep, checked as HTML (every figure embedded, nothing loaded from
elsewhere) and in a real browser (headless Chromium, when installed)."""

from __future__ import annotations

import base64
import json
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from harness.cli import main
from harness.report import detect_kind
from tests.conftest import harness_json, without_sweep_figures

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


class Tags(HTMLParser):
    """Every start tag with its attributes, and the text of <pre> blocks."""

    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.pre: list[str] = []
        self._in_pre = False

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        self._in_pre = tag == "pre"

    def handle_endtag(self, tag):
        self._in_pre = self._in_pre and tag != "pre"

    def handle_data(self, data):
        if self._in_pre:
            self.pre.append(data)

    def all(self, name):
        return [a for t, a in self.tags if t == name]


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """One small result document of every kind (written as the commands write them)."""
    root = tmp_path_factory.mktemp("results")
    docs = {}
    runs = {
        "compare": ["compare", "pentagon-bounce", "--engine", "linear", "--t-end", "0.5"],
        "bench": ["bench", "pentagon-bounce", "--engine", "linear", "--t-end", "0.3"],
        "fidelity": ["fidelity", "pentagon-bounce", "--engine", "mujoco", "--dt", "1e-3"],
        "stress": ["stress", "--case", "grazing", "--engine", "reference"],
    }
    runs["bench"] += ["--repeats", "1"]
    # horizon ensembles of 4 members, not 24: these tests read the document's fields
    runs["fidelity"] += ["--eps-grid", "1:1e-2:3", "--horizon-runs", "4"]
    for kind, argv in runs.items():
        docs[kind] = root / f"{kind}.json"
        harness_json(argv, docs[kind])
    sweep_root = root / "sweep"
    argv = ["sweep", "exponent", "--gyration", "0.3:0.5:2", "--restitution", "0.3:0.6:2"]
    argv += ["--samples", "2", "--engine", "linear", "--workers", "1", "--out", str(sweep_root)]
    with pytest.MonkeyPatch.context() as monkeypatch:
        # the report draws the sweep's map from its document, not from the sweep's PNGs
        without_sweep_figures(monkeypatch)
        harness_json(argv, root / "sweep.json")
    docs["sweep"] = root / "sweep.json"
    docs["sweep_dir"] = sweep_root / "linear"
    return docs


@pytest.fixture(scope="module")
def report(results, tmp_path_factory):
    """A report of every kind of result."""
    out = tmp_path_factory.mktemp("report") / "report.html"
    inputs = [str(results[k]) for k in ("compare", "bench", "fidelity", "stress", "sweep")]
    assert main(["report", *inputs, "--out", str(out)]) == 0
    return out


def test_every_result_document_says_what_it_is_and_where_it_came_from(results):
    for kind in ("compare", "bench", "fidelity", "stress", "sweep"):
        doc = json.loads(results[kind].read_text())
        assert detect_kind(doc) == kind
        prov = doc["provenance"]
        assert prov["command"].startswith(f"harness {kind}")
        assert {"euler-disk-harness", "numpy", "mujoco", "pybullet"} <= set(prov["versions"])
        assert prov["created"][:2] == "20" and "CPUs" in prov["host"]


def test_documents_without_a_kind_are_recognised_by_their_fields(results):
    for kind in ("compare", "bench", "stress", "sweep", "fidelity"):
        doc = json.loads(results[kind].read_text())
        doc.pop("kind", None)
        assert detect_kind(doc) == kind
    assert detect_kind({"hello": 1}) is None and detect_kind([1, 2]) is None


def test_report_embeds_every_figure_and_loads_nothing_from_elsewhere(report):
    html = report.read_text()
    tags = Tags()
    tags.feed(html)
    images = tags.all("img")
    assert len(images) == 4  # work-precision, alpha*, matched fractions, exponent map
    for img in images:
        head, _, data = img["src"].partition(",")
        assert head == "data:image/png;base64" and img.get("alt")
        assert base64.b64decode(data)[:8] == PNG_MAGIC
    assert not tags.all("script") and not tags.all("link") and not tags.all("iframe")
    for _, attrs in tags.tags:
        for name in ("src", "href"):
            value = attrs.get(name) or ""
            assert not value.startswith(("http:", "https:", "//")), value
    assert "@import" not in html and "url(" not in html


def test_report_shows_each_command_its_versions_and_verdicts(report, results):
    html = report.read_text()
    tags = Tags()
    tags.feed(html)
    commands = "".join(tags.pre)
    for kind in ("compare", "bench", "fidelity", "stress", "sweep"):
        assert json.loads(results[kind].read_text())["provenance"]["command"] in commands
    assert "harness report" in commands  # the report's own command
    verdict = json.loads(results["compare"].read_text())["engines"][0]["verdict"]
    assert verdict in html.replace("&#x27;", "'")
    assert len(tags.all("table")) >= 10


def test_versions_are_listed_once_for_the_whole_report(report):
    html = report.read_text()
    assert html.count("versions (importlib.metadata)") == 1
    # every result made by this install: its section points at that table
    assert html.count("Versions: as in the table at the end of the report.") == 5


def test_a_section_lists_the_versions_that_differ(results):
    from harness.report.sections import provenance_section

    doc = json.loads(results["bench"].read_text())
    shared = dict(doc["provenance"]["versions"])
    shared["numpy"] = "0.0"  # the report's table says otherwise
    html = provenance_section(doc, shared_versions=shared)
    assert "versions that differ" in html and doc["provenance"]["versions"]["numpy"] in html


def test_fidelity_ladder_has_one_narrow_column_per_scale(report, results):
    html = report.read_text()
    eps = json.loads(results["fidelity"].read_text())["eps"]
    assert html.count("<th class=v>α ") == len(eps)  # written vertically: fits the page


def test_a_sweep_directory_reports_what_its_json_summary_reports(results, tmp_path, capsys):
    from harness.report import load_inputs

    [from_dir] = load_inputs(results["sweep_dir"])
    [from_json] = load_inputs(results["sweep"])
    assert from_dir.kind == from_json.kind == "sweep"
    assert from_dir.doc["points"] == from_json.doc["points"]
    assert from_dir.rebuilt_command.startswith("harness sweep exponent --n 3 --gyration 0.3:0.5:2")
    out = tmp_path / "sweep.html"
    assert main(["report", str(results["sweep_dir"]), "--out", str(out)]) == 0
    assert "rebuilt from the sweep" in out.read_text()


def test_recording_link_is_relative_to_the_report(results, tmp_path):
    doc = json.loads(results["compare"].read_text())
    rec = tmp_path / "recordings" / "cmp.rrd"
    rec.parent.mkdir()
    rec.write_bytes(b"rrd")
    doc["recording"] = str(rec)
    src = tmp_path / "cmp.json"
    src.write_text(json.dumps(doc))
    out = tmp_path / "out" / "r.html"
    assert main(["report", str(src), "--out", str(out)]) == 0
    hrefs = [a.get("href") for t, a in _tags(out) if t == "a"]
    assert "../recordings/cmp.rrd" in hrefs


def _tags(path: Path):
    tags = Tags()
    tags.feed(path.read_text())
    return tags.tags


def test_bad_inputs_and_an_existing_output_are_refused_with_one_line(tmp_path, capsys, report):
    not_json = tmp_path / "x.json"
    not_json.write_text("{")
    other = tmp_path / "y.json"
    other.write_text('{"hello": 1}')
    cases = [
        [str(not_json), "--out", str(tmp_path / "a.html")],
        [str(other), "--out", str(tmp_path / "a.html")],
        [str(tmp_path / "missing.json"), "--out", str(tmp_path / "a.html")],
        [str(other), "--out", str(tmp_path / "a.txt")],
    ]
    for argv in cases:
        assert main(["report", *argv]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "Traceback" not in err[0]
    before = report.read_bytes()
    assert main(["report", str(other), "--out", str(report)]) == 2
    assert report.read_bytes() == before  # never over a user's file without --force


# ----------------------------------------------------------------------------- browser

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
# Appended to a copy of the report for this test only (the report itself has no script):
# after loading, every image records its decoded size, or "broken".
PROBE = (
    "<script>window.addEventListener('load', () => { for (const img of document.images) "
    "img.setAttribute('data-probe', img.naturalWidth > 0 ? img.naturalWidth + 'x' + "
    "img.naturalHeight : 'broken'); });</script>"
)


def _chromium(args: list[str], profile: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.skipif(
    CHROMIUM is None,
    reason="headless Chromium is not installed (Debian: apt-get install -y chromium; "
    "`make browser`)",
)
def test_report_opens_in_headless_chromium_with_its_tables_and_images(report, tmp_path):
    probe = tmp_path / "probe.html"
    probe.write_text(report.read_text().replace("</body>", PROBE + "</body>"))
    dom = _chromium(["--virtual-time-budget=10000", "--dump-dom", probe.as_uri()], tmp_path / "p")
    assert dom.returncode == 0, dom.stderr[-2000:]
    tags = Tags()
    tags.feed(dom.stdout)
    source = Tags()
    source.feed(report.read_text())
    assert len(tags.all("table")) == len(source.all("table")) >= 10
    probes = [img.get("data-probe") for img in tags.all("img")]
    assert len(probes) == 4 and all(p and p != "broken" for p in probes), probes
    shot = tmp_path / "shot.png"
    done = _chromium(
        ["--window-size=1280,2400", "--hide-scrollbars", f"--screenshot={shot}", report.as_uri()],
        tmp_path / "p",
    )
    assert done.returncode == 0 and shot.exists(), done.stderr[-2000:]
    import matplotlib.image as mpimg

    pixels = mpimg.imread(shot)
    assert pixels.shape[:2] == (2400, 1280) and pixels.std() > 0.05  # a page, not a blank

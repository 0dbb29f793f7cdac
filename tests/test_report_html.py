"""`fricsim diagnose`'s report.html, opened as a user would: of the EMPS
diagnosis and of a hidden-effect case made by the independent simulator.
It parses by the HTML5 algorithm in strict mode (no parse error at all),
holds no script and reaches nothing outside itself, renders in a real
headless Chromium (installed by scripts/setup-browser.sh) to a screenshot
that is not blank, with every section in the rendered page, and its verdict
names the FMU variables with their units."""

from __future__ import annotations

import html
import re
import shutil
import subprocess
import sys
from pathlib import Path

import html5lib
import numpy as np
import pytest
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import cases  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FRICSIM = ROOT / "target" / "release" / "fricsim"
SECTIONS = {
    "verdict": "Verdict",
    "gap": "The gap shrinking",
    "where": "Where",
    "physics": "The physics",
    "candidates": "Candidates tried",
    "changes": "What changed",
}


def diagnose(system: Path, data: Path, out: Path, *extra: str) -> Path:
    assert FRICSIM.exists(), "needs target/release/fricsim: run ./build-fmu.sh"
    run = subprocess.run(
        [str(FRICSIM), "diagnose", str(system), str(data), "--out", str(out), *extra],
        capture_output=True, text=True,
    )
    assert run.returncode == 0, run.stderr
    return out


@pytest.fixture(scope="module")
def emps(tmp_path_factory) -> Path:
    return diagnose(
        ROOT / "examples" / "emps_nominal.ssd", ROOT / "examples" / "data" / "emps_train.csv",
        tmp_path_factory.mktemp("emps") / "report", "--heldout", str(ROOT / "examples" / "data" / "emps_test_pulses.csv"),
    )


@pytest.fixture(scope="module")
def hidden(tmp_path_factory) -> Path:
    work = tmp_path_factory.mktemp("hidden")
    data, ssd = cases.make(cases.draw("position_dependent", 0.1, 7), work)
    return diagnose(ssd, data, work / "report")


@pytest.fixture(params=["emps", "hidden"])
def report(request) -> Path:
    return request.getfixturevalue(request.param)


def chromium() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    assert found, "Chromium is missing: scripts/setup-browser.sh installs it"
    return found


def headless(out_dir: Path, *args: str) -> subprocess.CompletedProcess:
    # the flags a closed network needs (no background connections), and a
    # profile of its own
    return subprocess.run(
        [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", f"--user-data-dir={out_dir / 'chromium-profile'}", *args],
        capture_output=True, text=True, timeout=120,
    )


def test_report_parses_without_a_single_html5_error(report):
    text = (report / "report.html").read_text()
    parser = html5lib.HTMLParser(strict=True, namespaceHTMLElements=False)
    document = parser.parse(text)
    assert document.find("body") is not None
    ids = {e.get("id") for e in document.iter() if e.get("id")}
    assert set(SECTIONS) <= ids, set(SECTIONS) - ids


def test_report_is_self_contained(report):
    text = (report / "report.html").read_text()
    assert "<script" not in text.lower()
    assert "<link" not in text.lower()
    # the only addresses are the SVG namespaces, which are names, not fetched
    addresses = set(re.findall(r"(?:https?|ftp)://[^\s\"'<>)]+", text))
    assert addresses <= {"http://www.w3.org/2000/svg", "http://www.w3.org/1999/xlink"}, addresses
    assert not re.search(r"""(?:src|href)\s*=\s*["'](?!#)""", text), "refers to another file"
    for png in ["gap", "fit", "law", "residual"]:
        assert (report / f"{png}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", png


def test_report_renders_in_chromium_with_every_section(report, tmp_path):
    page = (report / "report.html").resolve().as_uri()
    shot = tmp_path / "report.png"
    run = headless(tmp_path, f"--screenshot={shot}", "--window-size=1200,2400", page)
    assert shot.exists(), run.stderr[-2000:]
    image = Image.open(shot).convert("RGB")
    width, height = image.size
    assert (width, height) == (1200, 2400)
    pixels = np.asarray(image).reshape(-1, 3)
    not_white = int((pixels.min(axis=1) < 240).sum())
    assert not_white > 0.05 * len(pixels), f"nearly blank: {not_white} of {len(pixels)} pixels drawn"
    colours = len(np.unique(pixels[::7], axis=0))
    assert colours > 50, f"{colours} colours: too few for text and figures"
    # the page as Chromium built it: every section with its heading, and
    # the figures as SVG elements
    dom = headless(tmp_path, "--dump-dom", page).stdout
    tree = html5lib.parse(dom, namespaceHTMLElements=False)
    for section, heading in SECTIONS.items():
        found = [e for e in tree.iter("section") if e.get("id") == section]
        assert found, f"no section {section} in the rendered page"
        h2 = found[0].find("h2")
        assert h2 is not None and h2.text == heading, (section, h2 is not None and h2.text)
    assert len([e for e in tree.iter() if str(e.tag).endswith("svg")]) >= 4


def test_verdict_names_fmu_variables_with_units(emps, hidden):
    emps_html = (emps / "report.html").read_text()
    assert re.search(r"<code>sigma2_neg</code> = [-0-9.e]+ N.s/m \(was [-0-9.e]+ N.s/m\)", emps_html), "EMPS verdict"
    hidden_html = (hidden / "report.html").read_text()
    assert re.search(r"<code>scale_pos\[1\]</code> = [-0-9.e]+ \(was 1\)", hidden_html), "position verdict"
    # and the refitted system reruns with the command the report gives
    # (one on the training inputs, one on the held-out file's)
    section = emps_html[emps_html.index("Rerun the refitted system"):]
    commands = re.findall(r"<li><code>fricsim run ([^<]+)</code></li>", section)
    assert len(commands) == 2, "no rerun commands"
    for command in commands:
        args = html.unescape(command).split()
        assert {"--input", "--master", "--step", "--out"} <= set(args), args
        run = subprocess.run([str(FRICSIM), "run", *args, "--quiet"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        assert Path(args[args.index("--out") + 1]).stat().st_size > 0

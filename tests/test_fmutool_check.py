"""`fmutool -check` (fmu-manipulation-toolbox, pinned in requirements.txt)
finds no error in any shipped FMU.

The command line is run as a user runs it. Its two checkers are:
- "FMU Generic Conformity Checks": modelDescription.xml against the FMI 2.0
  XSD schema (every violation reported);
- "FMU Semantic Checks": the rules the schema cannot express (FMI 2.0
  §2.2.7, §2.2.8): unique variable names, allowed causality/variability
  pairs, allowed `initial` values and the presence or absence of `start`
  for each, `derivative` and `<ModelStructure>` references, and
  `<Outputs>` listing exactly the outputs.
Its log lines are `LEVEL | message`; each line is parsed, and the test
asserts both checkers ran, both gave their passing verdict, nothing was
logged at WARNING or above, and the exit status is 0. A copy of an FMU with
a broken model description must fail the same parse (so the test can fail).
"""

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from conftest import MODELS, fmu_path

FMUTOOL = Path(sys.executable).parent / "fmutool"
ALL = MODELS + ["Rig1D", "Rig2D"]
LINE = re.compile(r"^(DEBUG|INFO|WARNING|ERROR|CRITICAL)\s*\|\s?(.*)$")


def check(fmu):
    """Run `fmutool -input FMU -check`; return (exit status, [(level, message)])."""
    assert FMUTOOL.exists(), f"{FMUTOOL} is missing: run scripts/setup-venv.sh"
    result = subprocess.run([str(FMUTOOL), "-input", str(fmu), "-check"], capture_output=True, text=True)
    lines = []
    for raw in (result.stdout + result.stderr).splitlines():
        match = LINE.match(raw)
        # anything else (a traceback) is kept as an error
        lines.append((match.group(1), match.group(2).strip()) if match else ("ERROR", raw))
    return result.returncode, lines


@pytest.mark.parametrize("name", ALL)
def test_fmutool_check_finds_no_error(name):
    status, lines = check(fmu_path(name))
    problems = [f"{level}: {message}" for level, message in lines if level not in ("DEBUG", "INFO")]
    assert not problems, "\n".join(problems)
    assert status == 0
    messages = [m for _, m in lines]
    assert "=> FMU Generic Conformity Checks" in messages
    assert "This FMU seems to be compliant with FMI-2.0." in messages
    assert "=> FMU Semantic Checks" in messages
    assert "No semantic error against the FMI-2 standard." in messages


def test_fmutool_check_fails_on_a_broken_model_description(tmp_path):
    """Dahl with its Boolean output `sliding` made tunable (not allowed for
    an output) and an element the schema does not know."""
    source = fmu_path("Dahl")
    broken = tmp_path / "Dahl.fmu"
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(broken, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                changed = re.sub(r'(name="sliding"[^>]*)variability="discrete" initial="calculated"',
                                 r'\1variability="tunable"', text)
                changed = changed.replace("<Boolean/>", "<Boolean/><Unexpected/>", 1)
                assert changed != text and changed.count("tunable") > text.count("tunable")
                data = changed.encode()
            zout.writestr(item, data)
    status, lines = check(broken)
    errors = [m for level, m in lines if level == "ERROR"]
    assert status != 0
    assert any("'sliding'" in m and "tunable" in m for m in errors), errors
    assert any("Unexpected" in m for m in errors), errors
    assert "This FMU does not validate with FMI standard." in errors

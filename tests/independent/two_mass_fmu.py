"""Build TwoMassDrive.fmu from its hand-written C source.

The FMU is `host/tests/c/two_mass_drive/` (two_mass_drive.c and its
modelDescription.xml): a motor driving a load through a belt spring, with
friction on the load, FMI 2.0 Co-Simulation. `build(out_dir)` compiles the
source with the system C compiler (the flags of host/tests/common/mod.rs,
`compile_shared`, at -O2), lays out binaries/linux64/TwoMassDrive.so beside
the model description in a temporary folder and zips both into
out_dir/TwoMassDrive.fmu, only when the sources are newer than that file.

Usage: python3 tests/independent/two_mass_fmu.py [OUT_DIR]
(default OUT_DIR: target/independent), prints the .fmu's path.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SOURCE_DIR = ROOT / "host" / "tests" / "c" / "two_mass_drive"
SOURCE = SOURCE_DIR / "two_mass_drive.c"
DESCRIPTION = SOURCE_DIR / "modelDescription.xml"

#: The model identifier: the binary's and the .fmu's name.
MODEL_IDENTIFIER = "TwoMassDrive"

#: As compile_shared in host/tests/common/mod.rs, at -O2.
CFLAGS = ["-shared", "-fPIC", "-fvisibility=hidden", "-O2", "-Wall", "-Wextra"]


def check_description(description: Path = DESCRIPTION, source: Path = SOURCE) -> None:
    """Raise ValueError unless the model description's CoSimulation
    modelIdentifier is MODEL_IDENTIFIER (the binary's name) and its guid is
    the one the C source checks in fmi2Instantiate."""
    root = ET.parse(description).getroot()
    cs = root.find("CoSimulation")
    if cs is None:
        raise ValueError(f"{description}: no <CoSimulation> element")
    identifier = cs.get("modelIdentifier")
    if identifier != MODEL_IDENTIFIER:
        raise ValueError(
            f"{description}: modelIdentifier {identifier!r} does not match the binary "
            f"{MODEL_IDENTIFIER}.so"
        )
    found = re.search(r'^#define GUID "([^"]*)"', source.read_text(), re.MULTILINE)
    if found is None:
        raise ValueError(f"{source}: no #define GUID")
    if root.get("guid") != found.group(1):
        raise ValueError(
            f"{description}: guid {root.get('guid')!r} does not match {found.group(1)!r} in {source.name}"
        )


def build(out_dir: Path) -> Path:
    """Compile, lay out and zip TwoMassDrive.fmu into out_dir (created if
    need be); return its path. Nothing is done when the .fmu is at least as
    new as both sources."""
    out_dir = Path(out_dir)
    fmu = out_dir / f"{MODEL_IDENTIFIER}.fmu"
    newest = max(SOURCE.stat().st_mtime, DESCRIPTION.stat().st_mtime)
    if fmu.is_file() and fmu.stat().st_mtime >= newest:
        return fmu
    check_description()
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="two_mass_fmu_") as tmp:
        root = Path(tmp)
        binary = root / "binaries" / "linux64" / f"{MODEL_IDENTIFIER}.so"
        binary.parent.mkdir(parents=True)
        proc = subprocess.run(
            [os.environ.get("CC", "cc"), *CFLAGS, "-o", str(binary), str(SOURCE), "-lm"],
            capture_output=True,
            text=True,
        )
        if proc.returncode != 0:
            raise RuntimeError(f"cc failed on {SOURCE}:\n{proc.stderr}")
        if proc.stderr:
            print(proc.stderr, end="", file=sys.stderr)  # warnings: shown, not fatal
        # written beside the target and renamed, so a reader never sees half a zip
        partial = out_dir / f".{MODEL_IDENTIFIER}.fmu.{os.getpid()}.part"
        try:
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
                z.write(DESCRIPTION, "modelDescription.xml")
                z.write(binary, f"binaries/linux64/{MODEL_IDENTIFIER}.so")
            os.replace(partial, fmu)
        finally:
            partial.unlink(missing_ok=True)
    return fmu


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "independent"
    print(build(out))

"""Build the hand-written C plant FMUs (FMI 2.0 Co-Simulation) of the
any-plant cases: TwoMassDrive.fmu or ServoAxis.fmu.

Each plant is a folder of `host/tests/c/` (its C file and its
modelDescription.xml), the C file including `../common/linear_plant.h`:

- `two_mass`: `two_mass_drive/`, TwoMassDrive, a motor driving a load
  through a belt spring, friction on the load, driven by a motor force;
- `servo`: `servo_axis/`, ServoAxis, the same drive train under a PD
  position controller on the motor, driven by a position reference.

`build(out_dir, plant="two_mass")` compiles the source with the system C
compiler (the flags of host/tests/common/mod.rs, `compile_shared`, at -O2),
lays out binaries/linux64/<identifier>.so beside the model description in
a temporary folder and zips both into out_dir/<identifier>.fmu, only when
the sources (and the shared header) are newer than that file.

Usage: python3 tests/independent/two_mass_fmu.py [OUT_DIR [PLANT]]
(default OUT_DIR: target/independent, PLANT: two_mass), prints the .fmu's
path.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
C_DIR = ROOT / "host" / "tests" / "c"
#: What every plant's C file includes.
COMMON_HEADER = C_DIR / "common" / "linear_plant.h"


@dataclass(frozen=True)
class Plant:
    folder: str
    #: the model identifier: the binary's and the .fmu's name
    identifier: str

    @property
    def source(self) -> Path:
        return C_DIR / self.folder / f"{self.folder}.c"

    @property
    def description(self) -> Path:
        return C_DIR / self.folder / "modelDescription.xml"


PLANTS = {"two_mass": Plant("two_mass_drive", "TwoMassDrive"), "servo": Plant("servo_axis", "ServoAxis")}

#: As compile_shared in host/tests/common/mod.rs, at -O2.
CFLAGS = ["-shared", "-fPIC", "-fvisibility=hidden", "-O2", "-Wall", "-Wextra"]


def check_description(plant: str = "two_mass") -> None:
    """Raise ValueError unless the plant's model description has the
    plant's identifier (the binary's name) as CoSimulation modelIdentifier
    and the guid its C source checks in fmi2Instantiate."""
    p = PLANTS[plant]
    description, source, identifier = p.description, p.source, p.identifier
    root = ET.parse(description).getroot()
    cs = root.find("CoSimulation")
    if cs is None:
        raise ValueError(f"{description}: no <CoSimulation> element")
    declared = cs.get("modelIdentifier")
    if declared != identifier:
        raise ValueError(f"{description}: modelIdentifier {declared!r} does not match the binary {identifier}.so")
    found = re.search(r'^#define GUID "([^"]*)"', source.read_text(), re.MULTILINE)
    if found is None:
        raise ValueError(f"{source}: no #define GUID")
    if root.get("guid") != found.group(1):
        raise ValueError(
            f"{description}: guid {root.get('guid')!r} does not match {found.group(1)!r} in {source.name}"
        )


def build(out_dir: Path, plant: str = "two_mass") -> Path:
    """Compile, lay out and zip the plant's FMU (a key of PLANTS) into
    out_dir (created if need be); return its path. Nothing is done when the
    .fmu is at least as new as its sources and the shared header."""
    p = PLANTS[plant]
    out_dir = Path(out_dir)
    fmu = out_dir / f"{p.identifier}.fmu"
    newest = max(f.stat().st_mtime for f in (p.source, p.description, COMMON_HEADER))
    if fmu.is_file() and fmu.stat().st_mtime >= newest:
        return fmu
    check_description(plant)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f"{p.folder}_fmu_") as tmp:
        root = Path(tmp)
        binary = root / "binaries" / "linux64" / f"{p.identifier}.so"
        binary.parent.mkdir(parents=True)
        proc = subprocess.run(
            [os.environ.get("CC", "cc"), *CFLAGS, "-o", str(binary), str(p.source), "-lm"],
            capture_output=True,
            text=True,
        )
        if proc.returncode != 0:
            raise RuntimeError(f"cc failed on {p.source}:\n{proc.stderr}")
        if proc.stderr:
            print(proc.stderr, end="", file=sys.stderr)  # warnings: shown, not fatal
        # written beside the target and renamed, so a reader never sees half a zip
        partial = out_dir / f".{p.identifier}.fmu.{os.getpid()}.part"
        try:
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
                z.write(p.description, "modelDescription.xml")
                z.write(binary, f"binaries/linux64/{p.identifier}.so")
            os.replace(partial, fmu)
        finally:
            partial.unlink(missing_ok=True)
    return fmu


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "target" / "independent"
    print(build(out, sys.argv[2] if len(sys.argv) > 2 else "two_mass"))

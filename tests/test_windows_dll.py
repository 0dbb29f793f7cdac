"""The Windows binaries of the FMUs (issue 22): every dist/*.fmu carries
binaries/win64/<modelIdentifier>.dll beside binaries/linux64/<...>.so; the
DLL imports nothing but Windows system DLLs and exports the FMI functions
the .so exports; and the DLL, run under Wine by a small C importer
(tests/windows/fmi_driver.c compiled with MinGW-w64: LoadLibrary,
GetProcAddress), gives the same outputs as the .so run by the same C
source compiled natively (dlopen), to 1e-12 relative, with the same calls
refused (wrong state, NULL component, unknown value reference, NaN input,
wrong GUID). fmuResourceLocation is given as Windows file URIs
(file:///C:/..., file:/C:/..., percent-encoded) to the DLL and as Linux
ones to the .so.

FMI 3.0 (issue 45): dist/fmi3/<Name>.fmu holds the same two libraries
under binaries/x86_64-windows/ and binaries/x86_64-linux/, which export
every FMI 3.0 function; tests/windows/fmi3_driver.c, the FMI 3.0 twin of
the driver, runs the same plans through both, under Wine and natively:
the same outputs to 1e-12 relative, the same calls refused (wrong state,
NULL instance, unknown value reference, NaN, nValues that does not match,
wrong instantiation token), and on Linux the same bits as the FMI 2.0 run.

The tools (x86_64-w64-mingw32-gcc and -objdump, wine) are installed by
scripts/setup-windows.sh, which build-fmu.sh runs. Wine runs in a prefix of
its own under target/windows-test/ (created on the first run, without the
Mono and Gecko installers: no dialog), with WINEDEBUG=-all; the unpacked
FMUs lie on its drive C: under "fmu tests", a folder name with a space."""

import json
import os
import re
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from functools import lru_cache
from pathlib import Path
from urllib.parse import quote

import numpy as np
import pytest

import shipped

ROOT = Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
DRIVER_SOURCE = ROOT / "tests" / "windows" / "fmi_driver.c"
WORK = ROOT / "target" / "windows-test"
PREFIX = WORK / "wine-prefix"
# the FMUs are unpacked here, C:\fmu tests\<Name>\ under Wine
DRIVE_C_DIR = PREFIX / "drive_c" / "fmu tests"
FMU_NAMES = shipped.SHIPPED

# What a DLL of ours may import: Windows' own DLLs, present on every
# installation (API sets api-ms-win-* are Windows' too). Anything else,
# such as MinGW's libgcc_s_seh-1.dll or libwinpthread-1.dll, would have
# to be shipped beside the DLL, and FMI importers do not.
SYSTEM_DLLS = {
    "kernel32.dll", "ntdll.dll", "msvcrt.dll", "user32.dll", "advapi32.dll", "userenv.dll",
    "ws2_32.dll", "bcrypt.dll", "bcryptprimitives.dll", "dbghelp.dll", "shell32.dll", "ole32.dll",
}
# The FMI 2.0 Co-Simulation interface (FMI 2.0.4 §2.1 and §4.2).
FMI2_CS_FUNCTIONS = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal", "fmi2GetInteger",
    "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean",
    "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives",
    "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus",
}

# The FMI 3.0 functions an importer of Co-Simulation and Model Exchange
# looks up (FMI 3.0 sections 2.3, 3.2, 4.2; FMPy looks them all up).
FMI3_FUNCTIONS = {
    "fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation", "fmi3InstantiateScheduledExecution", "fmi3FreeInstance",
    "fmi3EnterInitializationMode", "fmi3ExitInitializationMode", "fmi3EnterEventMode",
    "fmi3Terminate", "fmi3Reset", "fmi3GetFloat32", "fmi3GetFloat64", "fmi3GetInt8",
    "fmi3GetUInt8", "fmi3GetInt16", "fmi3GetUInt16", "fmi3GetInt32", "fmi3GetUInt32",
    "fmi3GetInt64", "fmi3GetUInt64", "fmi3GetBoolean", "fmi3GetString", "fmi3GetBinary",
    "fmi3GetClock", "fmi3SetFloat32", "fmi3SetFloat64", "fmi3SetInt8", "fmi3SetUInt8",
    "fmi3SetInt16", "fmi3SetUInt16", "fmi3SetInt32", "fmi3SetUInt32", "fmi3SetInt64",
    "fmi3SetUInt64", "fmi3SetBoolean", "fmi3SetString", "fmi3SetBinary", "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies", "fmi3GetVariableDependencies", "fmi3GetFMUState",
    "fmi3SetFMUState", "fmi3FreeFMUState", "fmi3SerializedFMUStateSize", "fmi3SerializeFMUState",
    "fmi3DeserializeFMUState", "fmi3GetDirectionalDerivative", "fmi3GetAdjointDerivative",
    "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode", "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction", "fmi3GetShiftDecimal", "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal", "fmi3SetIntervalFraction", "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction", "fmi3EvaluateDiscreteStates", "fmi3UpdateDiscreteStates",
    "fmi3EnterContinuousTimeMode", "fmi3CompletedIntegratorStep", "fmi3SetTime",
    "fmi3SetContinuousStates", "fmi3GetContinuousStateDerivatives", "fmi3GetEventIndicators",
    "fmi3GetContinuousStates", "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators", "fmi3GetNumberOfContinuousStates", "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives", "fmi3DoStep", "fmi3ActivateModelPartition",
}
DRIVER3_SOURCE = ROOT / "tests" / "windows" / "fmi3_driver.c"

STEP = 1e-3
STOP = 4.0
w = 2 * np.pi
# Per case: the FMU, parameters (by name), and the inputs as functions of
# the time at the start of each step (held over the step).
CASES = {
    # The stick-slip benchmark's friction law (Canudas de Wit et al. 1995,
    # examples/lugre_1995.ssv) under a prescribed sliding velocity that
    # reverses twice a second and sticks around each reversal.
    "LuGre": ("LuGre", {"sigma0": 1e5, "sigma1": 316.22776601683796, "sigma2": 0.4, "Fc": 1.0,
                        "Fs": 1.5, "vs": 0.001},
              {"v": lambda t: 0.02 * np.sin(w * 0.5 * t)}),
    # LuGre with every extension (as in test_fmpy_equivalence.py): direction-
    # and position-dependent levels, velocity-dependent damping, normal force.
    "LuGre-extended": ("LuGre", {"direction_dependent": True, "Fc_neg": 0.8, "Fs_neg": 1.2,
                                 "position_dependent": True, "n_table": 4, "x_table[1]": 0.0,
                                 "x_table[2]": 0.25, "x_table[3]": 0.5, "x_table[4]": 1.0,
                                 "scale_pos[1]": 1.0, "scale_pos[2]": 1.2, "scale_pos[3]": 0.9,
                                 "scale_pos[4]": 1.1, "scale_neg[1]": 0.9, "scale_neg[2]": 1.0,
                                 "scale_neg[3]": 1.3, "scale_neg[4]": 1.0, "vd": 5e-3,
                                 "normal_force_form": True, "stribeck_exponent": 1.4},
                       {"v": lambda t: 2e-3 * np.sin(w * t), "x": lambda t: 0.3 + 0.2 * np.sin(0.5 * w * t),
                        "Fn": lambda t: 1.0 + 0.5 * np.cos(w * t)}),
    # the general exponent (a power law in the update)
    "Dahl": ("Dahl", {"alpha": 1.5}, {"v": lambda t: 5e-3 * np.sin(w * t)}),
    "ResetIntegrator": ("ResetIntegrator", {}, {"v": lambda t: 1e-3 * np.sin(w * t)}),
    # +-5e-8 m, beyond the pre-sliding range, with reversals; a seed of its own
    "Bristle": ("Bristle", {"seed": 7}, {"x": lambda t: 5e-8 * np.sin(w * t)}),
    "Bristle2D": ("Bristle2D", {}, {"v1": lambda t: 1e-3 * np.cos(w * t),
                                    "v2": lambda t: 5e-4 * np.sin(w * t)}),
    # through the zero-velocity band, the applied force above Fs in part
    "Classical": ("Classical", {}, {"v": lambda t: 2e-3 * np.sin(w * t),
                                    "F_app": lambda t: 3.0 * np.cos(1.5 * w * t)}),
    "BlimanSorine": ("BlimanSorine", {}, {"v": lambda t: 5e-3 * np.sin(w * t)}),
    "ElastoPlastic": ("ElastoPlastic", {}, {"v": lambda t: 2e-3 * np.sin(w * t)}),
    "MaxwellSlip": ("MaxwellSlip", {}, {"v": lambda t: 2e-4 * np.sin(w * t)}),
    "GMS": ("GMS", {}, {"v": lambda t: 2e-3 * np.sin(w * t)}),
    # the 1995 rig (defaults) with a friction force that holds and lets go, and dither
    "Rig1D": ("Rig1D", {"dither_amp": 0.01, "dither_freq": 7.0},
              {"F": lambda t: 1.2 + 0.3 * np.sin(w * t)}),
    "Rig2D": ("Rig2D", {}, {"F1": lambda t: 0.5 * np.sin(w * t), "F2": lambda t: 0.3 * np.cos(1.5 * w * t)}),
}
REQUIRED = {"LuGre", "Dahl", "ResetIntegrator", "Rig1D"}


def bits(x):
    return f"{struct.unpack('<Q', struct.pack('<d', float(x)))[0]:016x}"


def real(hex_bits):
    return struct.unpack("<d", struct.pack("<Q", int(hex_bits, 16)))[0]


def wine_env():
    env = dict(os.environ)
    env.update(WINEPREFIX=str(PREFIX), WINEDEBUG="-all",
               # no Mono or Gecko installer on the first run (they would ask)
               WINEDLLOVERRIDES="mscoree=;mshtml=")
    env.pop("DISPLAY", None)
    env.pop("WAYLAND_DISPLAY", None)
    return env


def run_to_files(command, name, env=None):
    """Run `command` with stdout and stderr into files under WORK (not
    pipes: Wine's helper processes inherit them and outlive the program,
    so reading a pipe to its end would wait for them); returns the exit
    status, stdout and stderr."""
    out, err = WORK / f"{name}.stdout", WORK / f"{name}.stderr"
    with open(out, "wb") as o, open(err, "wb") as e:
        # a guard against a hang only: a run takes seconds
        status = subprocess.run(command, stdout=o, stderr=e, stdin=subprocess.DEVNULL, env=env,
                                timeout=900).returncode
    return status, out.read_text(encoding="utf-8"), err.read_text(encoding="utf-8", errors="replace")


@pytest.fixture(scope="module", autouse=True)
def no_wine_process_outlives_the_module():
    """Stop the prefix's Wine server and its service processes
    (winedevice.exe and others) when the module is done, and wait for
    them. Left alone they outlive pytest and end a few seconds later on
    their own; one was seen to crash then, and glibc prints such a crash
    (`corrupted double-linked list`) on the terminal after pytest's last
    line, although every test passed."""
    yield
    if PREFIX.exists() and shutil.which("wineserver"):
        subprocess.run(["wineserver", "--kill"], env=wine_env(), timeout=60,
                       stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        subprocess.run(["wineserver", "--wait"], env=wine_env(), timeout=60,
                       stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@lru_cache(maxsize=None)
def tools():
    """Both drivers compiled, the Wine prefix created."""
    for tool in ["x86_64-w64-mingw32-gcc", "x86_64-w64-mingw32-objdump", "wine", "gcc", "nm"]:
        assert shutil.which(tool), f"{tool} is missing: run scripts/setup-windows.sh (build-fmu.sh does)"
    WORK.mkdir(parents=True, exist_ok=True)
    native, windows = WORK / "fmi_driver", WORK / "fmi_driver.exe"
    flags = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"]
    subprocess.run(["gcc", *flags, "-o", str(native), str(DRIVER_SOURCE), "-ldl", "-pthread"], check=True)
    subprocess.run(["x86_64-w64-mingw32-gcc", *flags, "-o", str(windows), str(DRIVER_SOURCE)], check=True)
    if not (PREFIX / "system.reg").exists():
        status, out, err = run_to_files(["wine", "wineboot", "--init"], "wineboot", wine_env())
        # the registry is written when the Wine server stops
        subprocess.run(["wineserver", "--wait"], env=wine_env(), check=True)
        assert status == 0 and (PREFIX / "system.reg").exists(), f"wineboot failed: {out}{err}"
    return native, windows


def model_description(name):
    with zipfile.ZipFile(DIST / f"{name}.fmu") as z:
        return ET.fromstring(z.read("modelDescription.xml"))


def variables(name):
    """name -> (value reference, causality, type, start) of every variable."""
    out = {}
    for v in model_description(name).iter("ScalarVariable"):
        typ = next(iter(v))
        out[v.get("name")] = (int(v.get("valueReference")), v.get("causality"), typ.tag, typ.get("start"))
    return out


@lru_cache(maxsize=None)
def unpack(name):
    """The FMU unpacked to C:\\fmu tests\\<name>\\ of the Wine prefix, afresh
    once per test session: the prefix outlives the session, and binaries
    left from an earlier build would be run against today's model
    description."""
    target = DRIVE_C_DIR / name
    shutil.rmtree(target, ignore_errors=True)
    with zipfile.ZipFile(DIST / f"{name}.fmu") as z:
        z.extractall(target)
    return target


def plan_text(case):
    fmu, parameters, inputs = CASES[case]
    md = model_description(fmu)
    table = variables(fmu)
    lines = [f"guid {md.get('guid')}"]
    for pname, value in parameters.items():
        vr, causality, typ, _ = table[pname]
        assert causality == "parameter", pname
        if typ == "Real":
            lines.append(f"real {vr} {bits(value)}")
        else:
            lines.append(f"{typ.lower()} {vr} {int(value)}")
    for iname in inputs:
        vr, causality, typ, _ = table[iname]
        assert causality == "input" and typ == "Real", iname
        lines.append(f"input {vr}")
    lines.append(f"nan_input {table[next(iter(inputs))][0]}")
    outputs = [(n, v) for n, v in table.items() if v[1] == "output"]
    for _, (vr, _, typ, _) in outputs:
        lines.append(f"output {typ.lower()} {vr}")
    n_steps = round(STOP / STEP)
    lines.append(f"steps {n_steps}")
    for n in range(n_steps):
        t = n * STEP
        lines.append(" ".join(["step", bits(STEP)] + [bits(f(t)) for f in inputs.values()]))
    return "\n".join(lines) + "\n", [n for n, _ in outputs], [v[2] for _, v in outputs]


def parse(stdout):
    rows, checks, logs, other = [], [], [], {}
    for line in stdout.splitlines():
        word, _, rest = line.partition(" ")
        if word == "o":
            rows.append(rest.split())
        elif word == "check":
            checks.append(rest.split())
        elif word == "log":
            status, category, message = rest.split(" ", 2)
            logs.append((int(status), category, message))
        elif word in ("version", "platform", "steps", "failures"):
            other[word] = rest
    return rows, checks, logs, other


def uris(fmu, windows):
    """fmuResourceLocation of the run, then the further forms tried."""
    if windows:
        base = f"C:/fmu%20tests/{fmu}/resources"
        return [f"file:///{base}",
                [f"file:///{base}", f"file:/{base}", "file:///C:/fmu%20tests/R%C3%A9sum%C3%A9/resources",
                 f"C:\\fmu tests\\{fmu}\\resources"]]
    path = quote(str(DRIVE_C_DIR / fmu / "resources"))
    return [f"file://{path}",
            [f"file://{path}", f"file:{path}", "file:///tmp/R%C3%A9sum%C3%A9/resources",
             str(DRIVE_C_DIR / fmu / "resources")]]


@lru_cache(maxsize=None)
def run(case, windows, wine_debug=None):
    native, exe = tools()
    fmu = CASES[case][0]
    root = DRIVE_C_DIR / fmu
    unpack(fmu)
    identifier = model_description(fmu).find("CoSimulation").get("modelIdentifier")
    text, names, types = plan_text(case)
    plan = root / f"plan-{case}.txt"
    plan.write_text(text)
    location, others = uris(fmu, windows)
    if windows:
        windows_dir = f"C:\\fmu tests\\{fmu}"
        command = ["wine", str(exe), f"{windows_dir}\\binaries\\win64\\{identifier}.dll",
                   f"{windows_dir}\\{plan.name}", location, *others]
        env = wine_env()
        if wine_debug:
            env["WINEDEBUG"] = wine_debug
        status, out, err = run_to_files(command, f"{case}-win64", env)
    else:
        command = [str(native), str(root / "binaries" / "linux64" / f"{identifier}.so"), str(plan),
                   location, *others]
        status, out, err = run_to_files(command, f"{case}-linux64")
    rows, checks, logs, other = parse(out)
    return {"status": status, "stdout": out, "stderr": err, "rows": rows, "checks": checks, "logs": logs,
            "other": other, "names": names, "types": types, "others": others}


@pytest.mark.parametrize("name", FMU_NAMES)
def test_fmu_holds_both_platforms(name):
    identifier = model_description(name).find("CoSimulation").get("modelIdentifier")
    with zipfile.ZipFile(DIST / f"{name}.fmu") as z:
        entries = sorted(z.namelist())
        dll = z.read(f"binaries/win64/{identifier}.dll")
        so = z.read(f"binaries/linux64/{identifier}.so")
    assert entries == sorted(["modelDescription.xml", f"binaries/linux64/{identifier}.so",
                              f"binaries/win64/{identifier}.dll"])
    # a PE image for x86-64 and an ELF image for x86-64
    pe = struct.unpack_from("<I", dll, 0x3C)[0]
    assert dll[:2] == b"MZ" and dll[pe:pe + 4] == b"PE\0\0"
    assert struct.unpack_from("<H", dll, pe + 4)[0] == 0x8664, "IMAGE_FILE_MACHINE_AMD64"
    assert struct.unpack_from("<H", dll, pe + 22)[0] & 0x2000, "IMAGE_FILE_DLL"
    assert so[:4] == b"\x7fELF" and struct.unpack_from("<H", so, 18)[0] == 62, "EM_X86_64"


@pytest.mark.parametrize("name", FMU_NAMES)
def test_dll_imports_only_windows_system_dlls_and_exports_the_fmi_functions(name, tmp_path):
    tools()
    identifier = model_description(name).find("CoSimulation").get("modelIdentifier")
    with zipfile.ZipFile(DIST / f"{name}.fmu") as z:
        z.extractall(tmp_path)
    dll = tmp_path / "binaries" / "win64" / f"{identifier}.dll"
    dump = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(dll)], capture_output=True, text=True,
                          check=True).stdout
    imports = {m.lower() for m in re.findall(r"DLL Name: (\S+)", dump)}
    assert "kernel32.dll" in imports, dump  # the import table was read
    foreign = {d for d in imports if d not in SYSTEM_DLLS and not d.startswith("api-ms-win-")}
    assert not foreign, f"{dll.name} imports DLLs that are not Windows': {sorted(foreign)}"
    table = dump.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    exported = set(re.findall(r"\]\s+(\S+)", table))
    assert FMI2_CS_FUNCTIONS <= exported, sorted(FMI2_CS_FUNCTIONS - exported)
    so = tmp_path / "binaries" / "linux64" / f"{identifier}.so"
    so_exports = {line.split()[-1] for line in subprocess.run(
        ["nm", "-D", "--defined-only", str(so)], capture_output=True, text=True, check=True).stdout.splitlines()}
    # the same FMI functions on both platforms (FMI 2.0's and FMI 3.0's: the
    # library serves dist/fmi3/ too), and nothing else exported
    assert {f for f in so_exports if f.startswith(("fmi2", "fmi3"))} == exported
    assert FMI3_FUNCTIONS <= exported, sorted(FMI3_FUNCTIONS - exported)


def test_every_fmu_has_a_case():
    assert {c[0] for c in CASES.values()} == set(FMU_NAMES) >= REQUIRED
    assert sorted(p.stem for p in DIST.glob("*.fmu")) == sorted(FMU_NAMES)


def wine_level_failure(r):
    """A Wine run whose program reported every check passed and every
    step made ("failures 0", "steps N" at its very end) and yet exited
    non-zero: the exit status came from Wine's side of the process (seen
    once in many runs, with an empty stderr), not from the driver, whose
    only non-zero exits follow a failed check or a message on stderr."""
    return (r["status"] != 0 and r["other"].get("failures") == "0"
            and int(r["other"].get("steps", -1)) == round(STOP / STEP) and not r["stderr"].strip())


@pytest.mark.parametrize("case", list(CASES))
def test_windows_dll_under_wine_equals_linux_so(case):
    win, lin = run(case, True), run(case, False)
    if wine_level_failure(win):
        # run once more, with Wine's error channel on for the record; every
        # assertion below then holds for that run, its exit status too
        first = win
        win = run(case, True, wine_debug="err+all")
        print(f"{case}: Wine exited {first['status']} after a clean run; rerun: exit {win['status']}\n"
              f"{win['stderr'][-3000:]}")
    for platform, r in (("win64", win), ("linux64", lin)):
        failed = [c for c in r["checks"] if c[-1] != "ok"]
        tail = "\n".join(r["stdout"].splitlines()[-5:])
        assert r["status"] == 0 and not failed, (
            f"{platform}: exit {r['status']}, {failed}, {r['other']}\nstdout ends:\n{tail}\nstderr:\n{r['stderr']}")
        assert r["other"]["version"] == "2.0" and r["other"]["platform"] == "default", r["other"]
        assert int(r["other"]["steps"]) == round(STOP / STEP), r["other"]
        assert len(r["rows"]) == round(STOP / STEP)
    # The same calls were refused on both: wrong state, NULL component,
    # unknown value reference, NaN input; the wrong GUID gave no instance.
    assert [c[:3] for c in win["checks"]] == [c[:3] for c in lin["checks"]]
    refused = {c[0] for c in win["checks"] if c[2] == "3"}
    assert refused == {"do_step_before_initialization", "exit_initialization_before_enter",
                       "set_real_unknown_vr", "get_real_unknown_vr", "get_real_null_component",
                       "do_step_null_component", "set_real_nan_input"}, refused
    assert ["instantiate_wrong_guid_is_null", "1", "1", "ok"] in win["checks"]
    assert ["nan_left_input_unchanged", "1", "1", "ok"] in win["checks"]
    # Each refusal was logged with its reason, on both platforms alike.
    errors = [(s, m) for s, c, m in win["logs"] if s == 3]
    assert errors == [(s, m) for s, c, m in lin["logs"] if s == 3]
    assert any("unknown fmuGUID" in m for _, m in errors), errors
    assert any("fmi2DoStep" in m and "Instantiated" in m for _, m in errors), errors
    assert any("NaN" in m or "not finite" in m for _, m in errors), errors

    assert [row[0] for row in win["rows"]] == [row[0] for row in lin["rows"]]
    worst = 0.0
    for i, (name, typ) in enumerate(zip(win["names"], win["types"])):
        if typ != "Real":
            column_w = [row[i + 1] for row in win["rows"]]
            assert column_w == [row[i + 1] for row in lin["rows"]], f"{case}.{name}"
            continue
        a = np.array([real(row[i + 1]) for row in win["rows"]])
        b = np.array([real(row[i + 1]) for row in lin["rows"]])
        assert np.all(np.isfinite(a)) and np.all(np.isfinite(b)), f"{case}.{name}"
        scale = max(np.max(np.abs(b)), 1e-300)
        err = np.max(np.abs(a - b)) / scale
        worst = max(worst, err)
        assert err <= 1e-12, f"{case}.{name}: Windows vs Linux relative difference {err:.3e}"
    # the law was exercised: its first output (the force, the rig's velocity or
    # position) moved
    first = np.array([real(row[1]) for row in lin["rows"]])
    assert np.ptp(first) > 0, f"{case}.{win['names'][0]} never moved"
    record = WORK / "differences.json"
    seen = json.loads(record.read_text()) if record.exists() else {}
    seen[case] = worst
    record.write_text(json.dumps(seen, indent=1, sort_keys=True))


@pytest.mark.parametrize("fmu", ["LuGre", "Rig1D"])
def test_resource_locations(fmu):
    """The run's location file:///C:/fmu%20tests/<FMU>/resources, the form
    without authority file:/C:/..., a percent-encoded non-ASCII name and a
    bare Windows path (not a URI): each instantiates the DLL under Wine, and
    each is logged with the directory it names or why it names none. The
    .so gets the Linux forms."""
    for windows in (True, False):
        r = run(fmu, windows)
        uri_checks = [c for c in r["checks"] if c[0] == "instantiate_with_uri"]
        assert len(uri_checks) == 4 and all(c[-1] == "ok" for c in uri_checks), r["checks"]
        messages = [m for s, c, m in r["logs"] if c == "logCalls" and m.startswith("fmi2Instantiate: ")]
        if windows:
            d = f"C:\\fmu tests\\{fmu}\\resources"
            expected = [
                f'fmuResourceLocation "file:///C:/fmu%20tests/{fmu}/resources" is the directory "{d}" '
                "(not read: this model uses no resources)",
                f'fmuResourceLocation "file:/C:/fmu%20tests/{fmu}/resources" is the directory "{d}" '
                "(not read: this model uses no resources)",
                'fmuResourceLocation "file:///C:/fmu%20tests/R%C3%A9sum%C3%A9/resources" is the directory '
                '"C:\\fmu tests\\Résumé\\resources" (not read: this model uses no resources)',
                f'fmuResourceLocation "{d}" is not a file: URI; accepted: this model uses no resources',
            ]
        else:
            d = str(DRIVE_C_DIR / fmu / "resources")
            q = quote(d)
            expected = [
                f'fmuResourceLocation "file://{q}" is the directory "{d}" (not read: this model uses no resources)',
                f'fmuResourceLocation "file:{q}" is the directory "{d}" (not read: this model uses no resources)',
                'fmuResourceLocation "file:///tmp/R%C3%A9sum%C3%A9/resources" is the directory '
                '"/tmp/Résumé/resources" (not read: this model uses no resources)',
                f'fmuResourceLocation "{d}" is not a file: URI; accepted: this model uses no resources',
            ]
        assert messages == [f"fmi2Instantiate: {m}" for m in expected], messages


def test_every_shipped_fmu_has_a_case():
    shipped.covers({fmu for fmu, _, _ in CASES.values()}, shipped.SHIPPED, "CASES")


# ---- FMI 3.0: dist/fmi3/<Name>.fmu, the same libraries ---------------------------

@lru_cache(maxsize=None)
def tools3():
    """The FMI 3.0 driver compiled for both platforms (and the Wine prefix)."""
    tools()
    native, windows = WORK / "fmi3_driver", WORK / "fmi3_driver.exe"
    flags = ["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror"]
    subprocess.run(["gcc", *flags, "-o", str(native), str(DRIVER3_SOURCE), "-ldl"], check=True)
    subprocess.run(["x86_64-w64-mingw32-gcc", *flags, "-o", str(windows), str(DRIVER3_SOURCE)],
                   check=True)
    return native, windows


def fmi3_description(name):
    with zipfile.ZipFile(DIST / "fmi3" / f"{name}.fmu") as z:
        return ET.fromstring(z.read("modelDescription.xml"))


@pytest.mark.parametrize("name", FMU_NAMES)
def test_fmi3_fmu_holds_the_same_libraries_under_fmi3_platform_tuples(name):
    identifier = fmi3_description(name).find("CoSimulation").get("modelIdentifier")
    with zipfile.ZipFile(DIST / "fmi3" / f"{name}.fmu") as z3, zipfile.ZipFile(DIST / f"{name}.fmu") as z2:
        assert sorted(z3.namelist()) == sorted(["modelDescription.xml",
                                                f"binaries/x86_64-linux/{identifier}.so",
                                                f"binaries/x86_64-windows/{identifier}.dll"])
        assert z3.read(f"binaries/x86_64-linux/{identifier}.so") == z2.read(f"binaries/linux64/{identifier}.so")
        assert z3.read(f"binaries/x86_64-windows/{identifier}.dll") == z2.read(f"binaries/win64/{identifier}.dll")
    # the same value references: the FMI 2.0 plan drives the FMI 3.0 FMU
    # (an FMI 3.0 array is its FMI 2.0 elements, from its value reference on)
    three = {}
    for v in fmi3_description(name).find("ModelVariables"):
        vr, dimension = int(v.get("valueReference")), v.find("Dimension")
        if dimension is None:
            three[v.get("name")] = vr
            continue
        inner = v.get("name")[4:-1] if v.get("name").startswith("der(") else None
        for i in range(int(dimension.get("start"))):
            three[f"der({inner}[{i + 1}])" if inner else f"{v.get('name')}[{i + 1}]"] = vr + i
    assert all(three[n] == vr for n, (vr, _, _, _) in variables(name).items())
    assert fmi3_description(name).get("instantiationToken") == model_description(name).get("guid")


def plan_text3(case):
    """`plan_text` for the FMI 3.0 FMU: a parameter that is an element of
    an FMI 3.0 array (`x_table[2]`) is set with its whole array, from the
    array's start values with the plan's elements changed (`reals`)."""
    text, names, types = plan_text(case)
    fmu, parameters, _ = CASES[case]
    arrays = {}
    for v in fmi3_description(fmu).find("ModelVariables"):
        if v.find("Dimension") is not None and v.get("start") is not None:
            arrays[v.get("name")] = (int(v.get("valueReference")), [float(x) for x in v.get("start").split()])
    table = variables(fmu)
    lines = text.splitlines()
    changed = {}
    for pname, value in parameters.items():
        base, _, index = pname.partition("[")
        if base in arrays and index:
            head, values = changed.setdefault(base, (arrays[base][0], list(arrays[base][1])))
            values[int(index[:-1]) - 1] = float(value)
            lines.remove(f"real {table[pname][0]} {bits(value)}")
    at = 1  # after the guid
    for head, values in changed.values():
        lines.insert(at, f"reals {head} {len(values)} " + " ".join(bits(x) for x in values))
    return "\n".join(lines) + "\n", names, types


@lru_cache(maxsize=None)
def unpack3(name, folder):
    """The FMI 3.0 FMU unpacked to C:\\fmu tests\\<folder>\\, afresh once per
    session (as `unpack`)."""
    target = DRIVE_C_DIR / folder
    shutil.rmtree(target, ignore_errors=True)
    with zipfile.ZipFile(DIST / "fmi3" / f"{name}.fmu") as z:
        z.extractall(target)
    return target


@lru_cache(maxsize=None)
def run3(case, windows):
    native, exe = tools3()
    fmu = CASES[case][0]
    folder = f"fmi3-{fmu}"
    root = unpack3(fmu, folder)
    identifier = fmi3_description(fmu).find("CoSimulation").get("modelIdentifier")
    text, names, types = plan_text3(case)
    plan = root / f"plan-{case}.txt"
    plan.write_text(text)
    if windows:
        windows_dir = f"C:\\fmu tests\\{folder}"
        command = ["wine", str(exe), f"{windows_dir}\\binaries\\x86_64-windows\\{identifier}.dll",
                   f"{windows_dir}\\{plan.name}", f"{windows_dir}\\resources\\"]
        status, out, err = run_to_files(command, f"{case}-fmi3-win64", wine_env())
    else:
        command = [str(native), str(root / "binaries" / "x86_64-linux" / f"{identifier}.so"), str(plan),
                   str(root / "resources") + "/"]
        status, out, err = run_to_files(command, f"{case}-fmi3-linux64")
    rows, checks, logs, other = parse(out)
    return {"status": status, "stdout": out, "stderr": err, "rows": rows, "checks": checks, "logs": logs,
            "other": other, "names": names, "types": types}


@pytest.mark.parametrize("case", list(CASES))
def test_fmi3_windows_dll_under_wine_equals_linux_so_and_the_fmi2_run(case):
    win, lin = run3(case, True), run3(case, False)
    for platform, r in (("x86_64-windows", win), ("x86_64-linux", lin)):
        failed = [c for c in r["checks"] if c[-1] != "ok"]
        tail = "\n".join(r["stdout"].splitlines()[-5:])
        assert r["status"] == 0 and not failed, (
            f"{platform}: exit {r['status']}, {failed}, {r['other']}\nstdout ends:\n{tail}\nstderr:\n{r['stderr']}")
        assert r["other"]["version"] == "3.0", r["other"]
        assert len(r["rows"]) == round(STOP / STEP)
    assert [c[:3] for c in win["checks"]] == [c[:3] for c in lin["checks"]]
    refused = {c[0] for c in win["checks"] if c[2] == "3"}
    assert refused == {"do_step_before_initialization", "exit_initialization_before_enter",
                       "set_float64_unknown_vr", "get_float64_unknown_vr", "get_float64_nvalues_mismatch",
                       "get_float64_null_instance", "do_step_null_instance", "set_float64_nan_input"}, refused
    assert ["instantiate_wrong_token_is_null", "1", "1", "ok"] in win["checks"]
    assert ["nan_left_input_unchanged", "1", "1", "ok"] in win["checks"]
    errors = [(s, m) for s, c, m in win["logs"] if s == 3]
    assert errors == [(s, m) for s, c, m in lin["logs"] if s == 3]
    assert any("unknown instantiationToken" in m for _, m in errors), errors
    assert any("fmi3DoStep" in m and "Instantiated" in m for _, m in errors), errors
    assert any("nValues = 2 for 1 value references" in m for _, m in errors), errors
    # the same numbers on both platforms, and the same as the FMI 2.0 run of
    # the same plan, bit for bit on Linux
    fmi2 = run(case, False)
    assert lin["rows"] == fmi2["rows"], f"{case}: the FMI 3.0 run differs from the FMI 2.0 run"
    for i, (name, typ) in enumerate(zip(win["names"], win["types"])):
        a = [row[i + 1] for row in win["rows"]]
        b = [row[i + 1] for row in lin["rows"]]
        if typ != "Real":
            assert a == b, f"{case}.{name}"
            continue
        a, b = np.array([real(x) for x in a]), np.array([real(x) for x in b])
        assert np.all(np.isfinite(a)), f"{case}.{name}"
        err = np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)
        assert err <= 1e-12, f"{case}.{name}: Windows vs Linux relative difference {err:.3e}"
    first = np.array([real(row[1]) for row in lin["rows"]])
    assert np.ptp(first) > 0, f"{case}.{win['names'][0]} never moved"


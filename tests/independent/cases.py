"""Hidden-effect datasets from an independent simulator, and the nominal
systems `fricsim diagnose` is given for them.

The data contract (docs/diagnose.md, "The data a diagnosis can use"): a mass pulled
through a spring by a measured actuator position, LuGre friction plus one
hidden effect or none, sampled at 1 kHz through a 1 µm encoder; the nominal
system is Rig1D (`actuator = 1`, driven by the data's `rig.x_act_in`) with
a LuGre FMU at the nominal parameters, connected v, x and F, strong coupling
(`newton`) at 1 ms. The nominal differs from the truth only by the hidden
effect.

The simulator is `lugre_rig.c` beside this file: plain C with its own
Runge–Kutta integrator, sharing no code with the FMUs. Every case draws its
rig (mass, spring, damper), its nominal friction (levels, stiffness,
damping ratio, with or without viscous and Stribeck terms) and its drive
(sines, a rounded triangle or ramped steps) from its seed, so that nothing
is tuned to one rig.

The magnitude ε of an effect is the RMS, along the effect-free trajectory,
of the change of the friction level it makes, as a fraction of Fc.

Any-plant cases (`<plant>_<effect>`, PLANT_KINDS): the same effects on a
plant that is not Rig1D, so that the diagnosis has no inverse dynamics
and fits by output error alone (issue 43). Two plants, different in
structure, each a hand-written C FMU (host/tests/c/, built by
two_mass_fmu.py) and a mode of the simulator:

- `two_mass`: TwoMassDrive, a motor driving a load through a belt spring,
  friction on the load, driven by a measured motor force (`drive.u`;
  measured: `drive.x_m`, `drive.x_l`);
- `servo`: ServoAxis, the same drive train under a PD position controller
  on the motor, driven by a position reference (`drive.r`; measured: both
  positions and the controller's force `drive.u`).

Memory cases (MEMORY_KINDS, not in the suite's default grid): the truth is
another friction law than the nominal's. `presliding_memory`: a Rig1D
whose true friction is the Generalized Maxwell-Slip law (Al-Bender,
Lampaert and Swevers 2005; lugre_rig.c's law=gms), presliding hysteresis
with nonlocal memory (Masing's rule, wiping-out), while the nominal is
LuGre. Both have the same levels Fc, Fs, vs, σ2, the same presliding
stiffness σ0 (the GMS elements built from it: lugre_rig.c's header) and
damping σ1 (GMS: shared among the elements by stiffness); GMS has 10
elements and a frictional lag Fc/C of 1-10 ms. The presliding distance
Fc/σ0 is 0.3-1 mm, and the actuator dithers (its spring force swinging by
±0.3-0.6·Fc) on top of the drive, so that the record has many reversals
inside presliding besides its gross slides. The case's "size" is that
change of structure: its magnitude is only a label and sizes nothing.

`presliding_drift`: a Rig1D whose true friction is the elasto-plastic
law (Dupont, Hayward, Armstrong and Altpeter 2002; lugre_rig.c's
law=elastoplastic), LuGre with a purely elastic range below the break-away
deflection z_ba, drawn as 0.5-0.9 of Fc/σ0, while the nominal is LuGre
with the same Fc, Fs, vs, σ0, σ1, σ2 (Fc/σ0 0.3-1 mm, as above). Under
a force below break-away LuGre creeps, the elasto-plastic contact does
not, so the record holds the spring force: the actuator (lugre_rig.c's
drive=hold) ramps to a position, holds there with a dither for 3-6 s
(at least 6 dither periods), slides the mass by 1-3 cm, rests, and again,
the levels and slides of either sign. The hold positions are set from the
truth itself, so that the spring force holds a chosen mean level,
±(0.5-0.65)·σ0·z_ba (0.25-0.59·Fc), and the dither swings it by
±(0.1-0.2)·σ0·z_ba, below the elastic limit σ0·z_ba throughout: the
truth is run up to the end of each rest, its friction force read there,
and the next hold position is the rest's plus (level − that force) over
the stiffness σ0·k/(σ0 + k) that holds the mass then (exact for the
elastic range, the mass at rest).
"""

from __future__ import annotations

import math
import os
import threading
import random
import subprocess
import zlib
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

#: Kinds of case: what is hidden, and how the nominal stands to the truth.
KINDS = (
    "none",
    "viscous",
    "stribeck",
    "direction_dependent",
    "position_dependent",
    "presliding_stiff_nominal",
    "presliding_soft_nominal",
)

#: The plants that are not Rig1D (cases.py's docstring): diagnose has no
#: inverse dynamics for them and fits by output error alone.
PLANTS = ("two_mass", "servo")

#: Every any-plant kind: each plant with each kind of KINDS.
PLANT_KINDS = tuple(f"{plant}_{kind}" for plant in PLANTS for kind in KINDS)

#: The any-plant kinds in the suite's default grid (its rows from before
#: there were more; their names and draws are kept).
GRID_PLANT_KINDS = ("two_mass_none", "two_mass_viscous")

#: Cases whose nominal friction is a Dahl FMU (the truth: LuGre with
#: Dahl's levels, Fs = Fc, σ1 = 0, plus the hidden effect): diagnose moves
#: the nominal to LuGre to add what Dahl cannot express.
DAHL_KINDS = ("dahl_none", "dahl_viscous")

#: Cases whose truth is another law than the nominal's (the docstring):
#: GMS's presliding memory, the elasto-plastic law's drift-free
#: presliding, each against a LuGre nominal. Not in KINDS, so in no
#: plant's kinds and not in the suite's default grid.
MEMORY_KINDS = ("presliding_memory", "presliding_drift")

#: The effect a kind should be diagnosed as (None: nothing to find).
EXPECTED: dict[str, str | None] = {
    "none": None,
    "viscous": "viscous",
    "stribeck": "stribeck",
    "direction_dependent": "direction_dependent",
    "position_dependent": "position_dependent",
    "presliding_stiff_nominal": "presliding",
    "presliding_soft_nominal": "presliding",
    "dahl_none": None,
    "dahl_viscous": "viscous",
    "presliding_memory": "presliding_memory",
    "presliding_drift": "elastic_presliding",
}
EXPECTED.update({f"{plant}_{kind}": EXPECTED[kind] for plant in PLANTS for kind in KINDS})


def plant_of(kind: str) -> str | None:
    """The plant of an any-plant kind (PLANTS), None for Rig1D."""
    return next((p for p in PLANTS if kind.startswith(p + "_")), None) if kind in PLANT_KINDS else None


def effect_of(kind: str) -> str:
    """The kind of KINDS a kind is on its plant or nominal law:
    `servo_stribeck` → `stribeck`, `dahl_viscous` → `viscous`."""
    for prefix in (*PLANTS, "dahl"):
        if kind.startswith(prefix + "_") and kind[len(prefix) + 1:] in KINDS:
            return kind[len(prefix) + 1:]
    return kind


SAMPLE = 1e-3
RESOLUTION = 1e-6

#: Coarse data: 200 Hz through a 10 µm encoder, where a Stribeck curve and
#: presliding leave overlapping signatures (the diagnosis must name the
#: right one or none, never the other).
COARSE_SAMPLE = 5e-3
COARSE_RESOLUTION = 1e-5

#: The kinds of the coarse rows.
COARSE_KINDS = ("none", "stribeck", "presliding_stiff_nominal", "presliding_soft_nominal")


def simulator() -> Path:
    """Build the simulator (once) and return its path."""
    out = ROOT / "target" / "independent" / "lugre_rig"
    src = HERE / "lugre_rig.c"
    if not out.exists() or out.stat().st_mtime < src.stat().st_mtime:
        out.parent.mkdir(parents=True, exist_ok=True)
        # built beside it and renamed into place: the test workers (and
        # the suite's threads) may build it at the same time, and none must
        # run a half-written one
        part = out.with_name(f"{out.name}.{os.getpid()}.{threading.get_ident()}")
        subprocess.run(
            [os.environ.get("CC", "cc"), "-O2", "-o", str(part), str(src), "-lm"],
            check=True,
        )
        os.replace(part, out)
    return out


@dataclass
class Case:
    kind: str
    magnitude: float
    seed: int
    duration: float = 40.0
    #: rig and drive
    rig: dict = field(default_factory=dict)
    drive: dict = field(default_factory=dict)
    #: LuGre parameters of the nominal model and of the truth
    nominal: dict = field(default_factory=dict)
    truth: dict = field(default_factory=dict)
    #: position table of the truth (x, scale), when position-dependent
    table: tuple = ()
    #: sampling period (s) and encoder step (m) of the data
    sample: float = SAMPLE
    resolution: float = RESOLUTION

    @property
    def coarse(self) -> bool:
        return self.sample != SAMPLE or self.resolution != RESOLUTION

    @property
    def name(self) -> str:
        rate = f"-{round(1 / self.sample)}hz-{round(self.resolution * 1e6)}um" if self.coarse else ""
        return f"{self.kind}-{round(self.magnitude * 100)}pct-s{self.seed}{rate}"


def draw(kind: str, magnitude: float, seed: int, duration: float = 40.0, coarse: bool = False) -> Case:
    """A case's rig, drive and nominal friction, drawn from its seed (the
    hidden effect is sized later, along the effect-free trajectory);
    `coarse`: sampled as [`COARSE_SAMPLE`], [`COARSE_RESOLUTION`] (the
    same rig and drive as the fine case of that seed)."""
    case = _draw(kind, magnitude, seed, duration)
    if coarse:
        case.sample, case.resolution = COARSE_SAMPLE, COARSE_RESOLUTION
    return case


def _draw(kind: str, magnitude: float, seed: int, duration: float) -> Case:
    rng = random.Random(zlib.crc32(f"{kind}/{seed}".encode()))
    m = rng.uniform(0.5, 4.0)
    k = rng.uniform(300.0, 3000.0)
    c = rng.choice([0.0, rng.uniform(0.1, 2.0)])
    drive = {
        "drive": rng.choice(["sines", "triangle", "steps"]),
        "amp": rng.uniform(0.02, 0.08),
        "period": rng.uniform(2.0, 6.0),
    }
    peak_speed = 2 * math.pi * drive["amp"] / drive["period"]
    fc = rng.uniform(1.0, 5.0)
    sigma0 = 10 ** rng.uniform(6.0, 7.0)
    zeta = rng.uniform(0.3, 1.0)
    nominal = {
        "Fc": fc,
        "Fs": fc * rng.choice([1.0, rng.uniform(1.1, 1.4)]),
        "vs": peak_speed * rng.uniform(0.1, 0.3),
        "sigma0": sigma0,
        "sigma1": 2 * zeta * math.sqrt(sigma0 * m),
        "sigma2": rng.choice([0.0, fc / peak_speed * rng.uniform(0.05, 0.3)]),
    }
    effect, plant = effect_of(kind), plant_of(kind)
    if effect == "presliding_soft_nominal":
        # a nominal presliding distance of 0.3-1 mm against a stiff truth
        nominal["sigma0"] = fc / rng.uniform(3e-4, 1e-3)
        nominal["sigma1"] = 2 * zeta * math.sqrt(nominal["sigma0"] * m)
    if effect == "presliding_stiff_nominal":
        nominal["sigma0"] = 1e6
        nominal["sigma1"] = 2 * zeta * math.sqrt(1e6 * m)
    if kind in MEMORY_KINDS:
        # a presliding distance Fc/σ0 of 0.3-1 mm, as the presliding cases
        nominal["sigma0"] = fc / rng.uniform(3e-4, 1e-3)
        nominal["sigma1"] = 2 * zeta * math.sqrt(nominal["sigma0"] * m)
    if kind == "presliding_memory":
        # reversals inside presliding: the actuator dithers, its spring
        # force swinging by ±(0.3-0.6)·Fc, at 0.2-0.6 s a cycle and no
        # faster than a quarter of the contact's own frequency
        # √((σ0 + k)/m) (so the mass follows it quasi-statically)
        own_period = 2 * math.pi * math.sqrt(m / (nominal["sigma0"] + k))
        drive["dither_amp"] = rng.uniform(0.3, 0.6) * fc / k
        drive["dither_period"] = max(rng.uniform(0.2, 0.6), 4 * own_period)
    if kind in DAHL_KINDS:
        nominal.update(Fs=fc, sigma1=0.0, sigma2=0.0)
    if plant == "two_mass":
        # motor 0.2-1 kg, load 1-4 kg, belt 1e4-5e4 N/m; the motor force
        # 3-6 times the friction level
        m_m = rng.uniform(0.2, 1.0)
        kb = rng.uniform(1e4, 5e4)
        drive = {"plant": "two_mass", "amp": fc * rng.uniform(3.0, 6.0), "period": rng.uniform(2.0, 5.0)}
        case = Case(kind, magnitude, seed, min(duration, 20.0),
                    {"m": m, "k": kb, "c": rng.uniform(5.0, 30.0), "m_m": m_m, "c_m": rng.uniform(0.5, 2.0)},
                    drive, nominal)
        peak_speed = drive["amp"] / ((m + m_m) * 2 * math.pi / drive["period"])
        nominal["vs"] = peak_speed * rng.uniform(0.1, 0.3)
        nominal["sigma2"] = 0.0
    elif plant == "servo":
        # the rig's drive as the reference of a PD loop on a motor of
        # 0.2-1 kg, belt 1e4-5e4 N/m to the carriage (the mass m); the
        # loop's bandwidth 4-10 Hz, damping ratio 0.5-1 on the total mass,
        # so a carriage held by friction sits Fc/Kp (50 µm to 11 mm) off
        m_m = rng.uniform(0.2, 1.0)
        w = 2 * math.pi * rng.uniform(4.0, 10.0)
        rig = {"m": m, "k": rng.uniform(1e4, 5e4), "c": rng.uniform(5.0, 30.0), "m_m": m_m,
               "c_m": rng.uniform(0.5, 2.0), "Kp": (m + m_m) * w * w, "Kd": 2 * rng.uniform(0.5, 1.0) * (m + m_m) * w}
        # the controller's force measured as a drive's current is, in
        # steps of 1 mN
        drive = {"plant": "servo", **drive, "force_resolution": 1e-3}
        case = Case(kind, magnitude, seed, min(duration, 20.0), rig, drive, nominal)
    else:
        case = Case(kind, magnitude, seed, duration, {"m": m, "k": k, "c": c}, drive, nominal)
    case.truth = dict(nominal)
    case._peak_speed = peak_speed  # type: ignore[attr-defined]
    case._zeta = zeta  # type: ignore[attr-defined]
    case._rng = rng  # type: ignore[attr-defined]
    return case


def run_simulator(case: Case, params: dict, out: Path, truth: bool = False, table=()) -> None:
    args = [str(simulator())]
    args += [f"{k}={v}" if isinstance(v, str) else f"{k}={v!r}" for k, v in {**case.rig, **params}.items()]
    args += [f"{k}={v}" for k, v in case.drive.items()]
    args += [f"duration={case.duration}", f"sample={case.sample}", f"resolution={case.resolution}"]
    args += [f"seed={case.seed}", f"truth={int(truth)}"]
    if table:
        xs, scales = table
        args += ["x_table=" + ",".join(repr(x) for x in xs), "scale=" + ",".join(repr(s) for s in scales)]
    with open(out, "w") as f:
        subprocess.run(args, check=True, stdout=f)


def read_columns(path: Path) -> dict[str, list[float]]:
    with open(path) as f:
        names = f.readline().strip().split(",")
        cols: list[list[float]] = [[] for _ in names]
        for line in f:
            for c, v in zip(cols, line.split(",")):
                c.append(float(v))
    return dict(zip(names, cols))


def rms(xs) -> float:
    xs = list(xs)
    return math.sqrt(sum(x * x for x in xs) / max(len(xs), 1))


def size_hidden_effect(case: Case, work: Path) -> None:
    """Run the effect-free truth, then set the hidden effect's amplitude so
    that the RMS change of the friction level along that trajectory is
    ε·Fc (closed forms: every shape is linear in its amplitude)."""
    rng: random.Random = case._rng  # type: ignore[attr-defined]
    eps, p = case.magnitude, case.nominal
    fc = p["Fc"]
    t = case.truth
    effect = effect_of(case.kind)
    if effect == "presliding_stiff_nominal":
        # 0.3-1.7 mm of presliding displacement, the damping ratio kept
        d = rng.uniform(3e-4, 1.7e-3)
        t["sigma0"] = fc / d
        t["sigma1"] = 2 * case._zeta * math.sqrt(t["sigma0"] * case.rig["m"])  # type: ignore[attr-defined]
        return
    if effect == "presliding_soft_nominal":
        # a stiff truth: 5-50 µm of presliding, 5 to 50 encoder steps (a
        # contact stiffer than the encoder resolves can be bounded, not sized)
        t["sigma0"] = fc / rng.uniform(5e-6, 5e-5)
        t["sigma1"] = 2 * case._zeta * math.sqrt(t["sigma0"] * case.rig["m"])  # type: ignore[attr-defined]
        return
    if effect == "none":
        return
    if case.kind == "presliding_memory":
        # the truth is GMS with the nominal's levels, σ0 and σ1: 10
        # elements, the frictional lag Fc/C 1-10 ms; nothing is sized
        t.update(law="gms", n_elements=10, C=fc / 10 ** rng.uniform(-3.0, -2.0))
        return
    if case.kind == "presliding_drift":
        # the truth is elasto-plastic with the nominal's parameters, its
        # break-away deflection 0.5-0.9 of Fc/σ0; the drive holds the
        # spring force below it (the docstring); nothing is sized
        t.update(law="elastoplastic", z_ba=rng.uniform(0.5, 0.9) * fc / p["sigma0"])
        hold_drive(case, work)
        return
    free = work / f"{case.name}.effect-free.csv"
    run_simulator(case, p, free, truth=True)
    d = read_columns(free)
    x = d["true_x"]
    v = [(b - a) / case.sample for a, b in zip(x, x[1:])]
    xm = [0.5 * (a + b) for a, b in zip(x, x[1:])]
    free.unlink()

    def level(vv: float) -> float:
        return p["Fc"] + (p["Fs"] - p["Fc"]) * math.exp(-((vv / p["vs"]) ** 2))

    if effect == "viscous":
        t["sigma2"] = p["sigma2"] + eps * fc / rms(v)
    elif effect == "stribeck":
        vs = p["vs"] if p["Fs"] > p["Fc"] else rms(v) * rng.uniform(0.2, 0.5)
        base = (p["Fs"] - p["Fc"]) * 0 + 0.0
        shape = rms(math.exp(-((vv / vs) ** 2)) for vv in v)
        t["vs"] = vs
        # the excess over the nominal's: Fs − Fc grows by a·Fc
        if p["Fs"] > p["Fc"]:
            # same vs: the change is a·Fc·exp(−(v/vs)²)
            t["Fs"] = p["Fs"] + eps * fc / shape
        else:
            t["Fs"] = fc + eps * fc / shape + base
    elif effect == "direction_dependent":
        neg = rms((level(vv) / fc if vv < 0 else 0.0) for vv in v)
        a = eps / neg
        t["Fc_neg"] = p["Fc"] * (1 + a)
        t["Fs_neg"] = p["Fs"] * (1 + a)
    elif effect == "position_dependent":
        lo, hi = min(xm), max(xm)
        knots = 5
        xs = [lo + (hi - lo) * i / (knots - 1) for i in range(knots)]
        pattern = [rng.uniform(-1, 1) for _ in range(knots)]
        mean = sum(pattern) / knots
        pattern = [q - mean for q in pattern]

        def interp(xx: float) -> float:
            if xx <= xs[0]:
                return pattern[0]
            for i in range(1, knots):
                if xx <= xs[i]:
                    u = (xx - xs[i - 1]) / (xs[i] - xs[i - 1])
                    return pattern[i - 1] + u * (pattern[i] - pattern[i - 1])
            return pattern[-1]

        a = eps / rms(interp(xx) * level(vv) / fc for xx, vv in zip(xm, v))
        case.table = (xs, [1 + a * q for q in pattern])
    else:
        raise ValueError(case.kind)


def hold_drive(case: Case, work: Path) -> None:
    """The drive of a presliding_drift case (the docstring), its hold
    positions set from the truth: case.drive becomes lugre_rig.c's
    drive=hold, and case._holds lists each hold as (start, end, level): the
    dithered interval (s) and the mean friction force it was set for."""
    rng: random.Random = case._rng  # type: ignore[attr-defined]
    m, k = case.rig["m"], case.rig["k"]
    fs, sigma0 = case.nominal["Fs"], case.nominal["sigma0"]
    limit = sigma0 * case.truth["z_ba"]  # the elastic limit of the force
    # the spring force per metre of actuator while the mass is held by
    # the contact's stiffness σ0 (elastic, at rest)
    k_held = k * sigma0 / (k + sigma0)
    own = 2 * math.pi * math.sqrt(m / (sigma0 + k))  # the contact's period

    def ms(seconds: float) -> int:  # every time on the 1 ms grid
        return max(1, round(1000 * seconds))

    # the dither as in presliding_memory: 0.2-0.6 s a cycle, no faster than
    # a quarter of the contact's own frequency; ramps and rests long enough
    # for the mass to follow and settle
    period, ramp, rest = ms(max(rng.uniform(0.2, 0.6), 4 * own)), ms(max(0.3, 2 * own)), ms(max(0.5, 6 * own))
    swing = rng.uniform(0.1, 0.2) * limit
    case.drive = {"drive": "hold", "dither_amp": swing / k_held, "dither_period": period / 1000}
    total = ms(case.duration)
    blocks = []  # (cycles, level, slide or None, slide time)
    now, direction = 0, rng.choice([-1, 1])
    while True:
        cycles = max(6, round(rng.uniform(3.0, 6.0) / (period / 1000)))
        level = rng.choice([-1, 1]) * rng.uniform(0.5, 0.65) * limit
        # 1-3 cm of the mass's travel, plus the spring's stretch from one
        # side's break-away to the other's
        slide = direction * (rng.uniform(0.01, 0.03) + 2 * fs / k)
        slide_ms = ms(2 * abs(slide) / (case._peak_speed * rng.uniform(0.7, 1.5)))  # type: ignore[attr-defined]
        if now + ramp + cycles * period + slide_ms + rest > total:
            # a last hold in what is left, when 6 periods fit
            cycles = (total - now - ramp) // period
            if cycles >= 6:
                blocks.append((cycles, level, None, 0))
            break
        blocks.append((cycles, level, slide, slide_ms))
        now += ramp + cycles * period + slide_ms + rest
        direction = -direction

    times, positions, dithered, holds = [0], [0.0], [], []

    def drive_to(end: int) -> dict:
        return {**case.drive, "hold_t": ",".join(repr(t / 1000) for t in times[:end]),
                "hold_x": ",".join(repr(x) for x in positions[:end]),
                "hold_dither": ",".join(str(d) for d in dithered[:end - 1])}

    def add(duration: int, position: float, dither: int) -> None:
        times.append(times[-1] + duration)
        positions.append(position)
        dithered.append(dither)

    # at the start the spring is relaxed and the contact unloaded
    force = 0.0
    for cycles, level, slide, slide_ms in blocks:
        hold = positions[-1] + (level - force) / k_held
        add(ramp, hold, 0)
        add(cycles * period, hold, 1)
        holds.append((times[-2] / 1000, times[-1] / 1000, level))
        if slide is None:
            break
        add(slide_ms, hold + slide, 0)
        add(rest, hold + slide, 0)
        # the truth up to the end of this rest: its friction force there
        part = Case(case.kind, case.magnitude, case.seed, times[-1] / 1000, case.rig, drive_to(len(times)),
                    case.nominal, case.truth, sample=case.sample, resolution=case.resolution)
        out = work / f"{case.name}.hold.csv"
        run_simulator(part, case.truth, out, truth=True)
        force = read_columns(out)["true_F"][-1]
        out.unlink()
    if times[-1] < total:
        add(total - times[-1], positions[-1], 0)
    case.drive = drive_to(len(times))
    case._holds = holds  # type: ignore[attr-defined]


def make(case: Case, work: Path) -> tuple[Path, Path]:
    """Write the case's data (and the noise-free truth beside it) and its
    nominal system; returns (data.csv, nominal.ssd)."""
    work.mkdir(parents=True, exist_ok=True)
    size_hidden_effect(case, work)
    truth_csv = work / f"{case.name}.truth.csv"
    run_simulator(case, case.truth, truth_csv, truth=True, table=case.table)
    d = read_columns(truth_csv)
    data = work / f"{case.name}.csv"
    columns = [c for c in d if c not in ("true_x", "true_F")]
    with open(data, "w") as f:
        f.write(",".join(columns) + "\n")
        for row in zip(*(d[c] for c in columns)):
            f.write(f"{row[0]:.6f}," + ",".join(f"{x:.9g}" for x in row[1:]) + "\n")
    ssd = work / f"{case.name}.ssd"
    plant = plant_of(case.kind)
    if plant:
        import two_mass_fmu

        fmu = two_mass_fmu.build(ROOT / "target" / "independent", plant)
        ssd.write_text((two_mass_ssd if plant == "two_mass" else servo_ssd)(case, fmu, x0=d["true_x"][0]))
    else:
        ssd.write_text(nominal_ssd(case, d["true_x"][0]))
    return data, ssd


def _real(name: str, value: float) -> str:
    return f'<ssv:Parameter name="{name}"><ssv:Real value="{value!r}"/></ssv:Parameter>'


def _component(name: str, source: Path, connectors: list[tuple[str, str, str]], parameters: str) -> str:
    """An SSD component: connectors (name, kind, unit), parameter XML."""
    conns = "".join(
        f'<ssd:Connector name="{n}" kind="{k}"><ssc:Real unit="{u}"/></ssd:Connector>' for n, k, u in connectors
    )
    return f"""      <ssd:Component name="{name}" source="{source}" type="application/x-fmu-sharedlibrary">
        <ssd:Connectors>{conns}</ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="{name}"><ssv:Parameters>{parameters}</ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
"""


def _ssd(case: Case, components: str, connections: list[tuple[str, str, str, str]]) -> str:
    """The system file: components, connections (from, port, to, port), the
    contract's co-simulation settings (newton at 1 ms)."""
    conns = "".join(
        f'<ssd:Connection startElement="{a}" startConnector="{b}" endElement="{c}" endConnector="{d}"/>'
        for a, b, c, d in connections
    )
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="{case.name}"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="{case.name}">
    <ssd:Elements>
{components}    </ssd:Elements>
    <ssd:Connections>{conns}</ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{case.duration}">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="1e-3" master="newton"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def _lugre(case: Case, dist: Path) -> str:
    p = case.nominal
    fr = "".join(_real(n, p[n]) for n in ["Fc", "Fs", "vs", "sigma0", "sigma1", "sigma2"])
    return _component("friction", dist / "LuGre.fmu", [("v", "input", "m/s"), ("x", "input", "m"), ("F", "output", "N")], fr)


def _plant_ssd(case: Case, plant_fmu: Path, parameters: list, connectors: list, dist: Path | None) -> str:
    """The nominal system of an any-plant case: the plant FMU as `drive`
    (its parameters, connectors) with LuGre on the load, connected v, x_l
    and F."""
    drive = _component("drive", plant_fmu, connectors, "".join(_real(n, v) for n, v in parameters))
    return _ssd(
        case,
        drive + _lugre(case, dist or ROOT / "dist"),
        [("drive", "v", "friction", "v"), ("drive", "x_l", "friction", "x"), ("friction", "F", "drive", "F")],
    )


#: The outputs both plants share (their carriage or load).
_PLANT_OUTPUTS = [("x_m", "output", "m"), ("x_l", "output", "m"), ("v", "output", "m/s")]


def two_mass_ssd(case: Case, plant_fmu: Path, dist: Path | None = None, x0: float = 0.0) -> str:
    """The nominal system of a two-mass case: TwoMassDrive (motor force u
    from the data) with LuGre on the load."""
    r = case.rig
    parameters = [("m_m", r["m_m"]), ("m_l", r["m"]), ("k_b", r["k"]), ("c_b", r["c"]), ("c_m", r["c_m"]),
                  ("x0", x0), ("h_max", 1e-4)]
    connectors = [("u", "input", "N"), ("F", "input", "N"), *_PLANT_OUTPUTS]
    return _plant_ssd(case, plant_fmu, parameters, connectors, dist)


def servo_ssd(case: Case, plant_fmu: Path, dist: Path | None = None, x0: float = 0.0) -> str:
    """The nominal system of a servo case: ServoAxis (position reference r
    from the data; the controller's force u an output, compared with the
    data's) with LuGre on the carriage."""
    r = case.rig
    parameters = [("m_m", r["m_m"]), ("m_l", r["m"]), ("k_g", r["k"]), ("c_g", r["c"]), ("c_m", r["c_m"]),
                  ("Kp", r["Kp"]), ("Kd", r["Kd"]), ("x0", x0), ("h_max", 1e-4)]
    connectors = [("r", "input", "m"), ("F", "input", "N"), *_PLANT_OUTPUTS, ("u", "output", "N")]
    return _plant_ssd(case, plant_fmu, parameters, connectors, dist)


def nominal_ssd(case: Case, x0: float, dist: Path | None = None) -> str:
    """The nominal system of a Rig1D case: Rig1D (actuator = 1, driven by
    the data's x_act_in) with LuGre (or Dahl for a Dahl case)."""
    dist = dist or ROOT / "dist"
    r, p = case.rig, case.nominal
    rig_parameters = "".join(
        _real(n, v) for n, v in [("m", r["m"]), ("c", r["c"]), ("k", r["k"]), ("x0", x0), ("v_a", 0.0)]
    ) + '<ssv:Parameter name="actuator"><ssv:Integer value="1"/></ssv:Parameter>'
    rig = _component(
        "rig",
        dist / "Rig1D.fmu",
        [("F", "input", "N"), ("x_act_in", "input", "m"), ("v", "output", "m/s"), ("x", "output", "m")],
        rig_parameters,
    )
    connections = [("rig", "v", "friction", "v"), ("friction", "F", "rig", "F")]
    if case.kind in DAHL_KINDS:
        friction = _component(
            "friction",
            dist / "Dahl.fmu",
            [("v", "input", "m/s"), ("F", "output", "N")],
            _real("sigma", p["sigma0"]) + _real("Fc", p["Fc"]) + _real("alpha", 1.0),
        )
    else:
        friction = _lugre(case, dist)
        connections.append(("rig", "x", "friction", "x"))
    return _ssd(case, rig + friction, connections)

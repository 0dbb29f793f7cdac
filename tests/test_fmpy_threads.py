"""One instance of each shipped FMU called from two threads at once through
FMPy (tests/concurrent_probe.py, in a child process so that a crash fails
the test). FMI 2.0 leaves concurrent calls into one instance undefined;
ours refuse the second call with fmi2Error and a message, and the instance
goes on unharmed. Before the instance guard, this corrupted the heap
(SIGSEGV, "double free") or panicked in fmi2GetFMUstate."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from shipped import SHIPPED
PROBE = Path(__file__).resolve().parent / "concurrent_probe.py"


@pytest.mark.parametrize("model", SHIPPED)
def test_a_second_thread_is_refused_and_nothing_breaks(model, tmp_path):
    run = subprocess.run([sys.executable, str(PROBE), model, str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"exit {run.returncode}\n{run.stderr[-3000:]}"
    out = json.loads(run.stdout.strip().splitlines()[-1])

    # Held inside a call (its logger waiting), the instance refuses every
    # call of another thread, naming the function.
    assert out["was_held"]
    assert out["nan"] == 3, "the held call itself fails: NaN"
    assert set(out["held_statuses"]) == {"fmi2DoStep", "fmi2GetReal", "fmi2SetReal", "fmi2GetFMUstate"}
    for function, status in out["held_statuses"].items():
        assert status == 3, (function, status)
        assert any(m.startswith(f"{function}: refused: another thread is inside a call")
                   for m in out["held_messages"]), (function, out["held_messages"])

    # Hammered from two threads: only fmi2OK and fmi2Error, every error a
    # logged refusal, and the instance still steps.
    hammer = out["hammer"]
    assert hammer["other"] == 0, hammer
    assert hammer["ok"] > 0, hammer
    assert out["refusals"] == hammer["error"], (out["refusals"], hammer)
    assert math.isfinite(out["after"])

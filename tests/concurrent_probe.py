"""Two threads calling one instance of a shipped FMU at once, through FMPy
(ctypes releases the GIL around each call, so the calls overlap).
Run by tests/test_fmpy_threads.py in a child process, so that a crash of
the FMU fails the test instead of ending pytest.

    python tests/concurrent_probe.py MODEL TMPDIR

prints one JSON object:
- held: the statuses of calls made while another thread is held inside a
  call on the same instance (its logger waits), and the messages logged;
- hammer: counts of fmi2OK and fmi2Error of two threads calling
  fmi2GetFMUstate / fmi2FreeFMUstate / fmi2GetReal / fmi2SetReal in a loop,
  and the number of refusals logged;
- after: whether the instance still steps."""

import json
import math
import sys
import threading
from pathlib import Path

from fmpy.fmi1 import FMICallException

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import CapturedInstance  # noqa: E402

REFUSAL = "another thread is inside a call"


def status_of(call):
    try:
        call()
        return 0
    except FMICallException as e:
        return e.status


def main(model, tmp):
    inst = CapturedInstance(model, Path(tmp))
    f = inst.fmu
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    f.exitInitializationMode()
    real_in = next(v for v in inst.md.modelVariables if v.causality == "input" and v.type == "Real")
    real_out = next(v for v in inst.md.modelVariables if v.causality == "output" and v.type == "Real")
    u, y = real_in.valueReference, real_out.valueReference

    # 1. One thread held inside a call: its logger waits for the other.
    # (CapturedInstance's logger appends to `inst.messages`: a list whose
    # append waits does it.)
    held, other_done = threading.Event(), threading.Event()

    class HoldingList(list):
        def append(self, item):
            super().append(item)
            if "must be finite" in item[2]:
                held.set()
                other_done.wait(timeout=60)

    results = {}

    def hold():
        results["nan"] = status_of(lambda: f.setReal([u], [math.nan]))

    t = threading.Thread(target=hold)
    inst.messages = HoldingList()
    t.start()
    was_held = held.wait(timeout=60)
    calls = {
        "fmi2DoStep": lambda: f.doStep(0.0, 1e-4),
        "fmi2GetReal": lambda: f.getReal([y]),
        "fmi2SetReal": lambda: f.setReal([u], [0.5]),
        "fmi2GetFMUstate": f.getFMUstate,
    }
    held_statuses = {name: status_of(call) for name, call in calls.items()} if was_held else {}
    other_done.set()
    t.join()
    held_messages = [m for s, _, m in inst.messages]
    inst.messages = []

    # 2. Two threads hammering.
    counts = {"ok": 0, "error": 0, "other": 0}
    lock = threading.Lock()

    def hammer(k):
        for i in range(3000):
            local = []
            try:
                s = f.getFMUstate()
                local.append(0)
                while status_of(lambda: f.freeFMUstate(s)) != 0:
                    local.append(3)
                local.append(0)
            except FMICallException as e:
                local.append(e.status)
            local.append(status_of(lambda: f.getReal([y])))
            local.append(status_of(lambda: f.setReal([u], [1e-6 * (k * 3000 + i)])))
            with lock:
                for s in local:
                    counts["ok" if s == 0 else "error" if s == 3 else "other"] += 1

    threads = [threading.Thread(target=hammer, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    refusals = sum(1 for s, _, m in inst.messages if s == 3 and REFUSAL in m)

    # 3. Still whole.
    f.setReal([u], [0.0])
    f.doStep(0.0, 1e-4)
    after = f.getReal([y])[0]
    inst.close()
    print(json.dumps({
        "was_held": was_held,
        "nan": results.get("nan"),
        "held_statuses": held_statuses,
        "held_messages": held_messages,
        "hammer": counts,
        "refusals": refusals,
        "after": after,
    }))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

"""`fricsim diagnose`'s progress line: drawn on stderr when stderr is a
terminal (here a pseudo-terminal), not when it is a pipe, and not with
-q. Each run is the slider table's diagnosis under a time limit of one
second (it takes several in full), so the three runs are quick."""

import fcntl
import os
import pty
import select
import struct
import subprocess
import termios

ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent
FRICSIM = ROOT / "target" / "release" / "fricsim"
SYSTEM = ROOT / "examples" / "slider_breakaway.ssd"
DATA = ROOT / "examples" / "data" / "slider_breakaway.csv"

# what only the progress line prints on stderr
PROGRESS = ("co-simulation", "elapsed", "diagnose:")


def command(out, *extra):
    assert FRICSIM.exists(), f"{FRICSIM} is missing: cargo build --release -p fricsim"
    return [str(FRICSIM), "diagnose", str(SYSTEM), str(DATA), "--out", str(out),
            "--time-limit", "1", *extra]


def run_with_stderr_on_a_terminal(args):
    """Run `args` with stderr on a pseudo-terminal of 200 columns (stdout
    to a pipe): its exit status, stdout, and all the terminal received."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 50, 200, 0, 0))
    proc = subprocess.Popen(args, cwd=ROOT, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    received = b""
    # read while it runs (a full terminal buffer would block its writes)
    while True:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # EIO: every copy of the slave end is closed
                break
            if not chunk:
                break
            received += chunk
        elif proc.poll() is not None:
            break
    os.close(master)
    stdout = proc.stdout.read().decode()
    proc.wait()
    return proc.returncode, stdout, received.decode(errors="replace")


def test_the_progress_line_is_drawn_on_a_terminal(tmp_path):
    status, stdout, terminal = run_with_stderr_on_a_terminal(command(tmp_path / "d"))
    assert status == 0, stdout + terminal
    for text in PROGRESS:
        assert text in terminal, f"{text!r} not in what the terminal received: {terminal!r}"
    # the stage and the time limit are named; the line is redrawn in place
    assert "time limit 1 s" in terminal, terminal
    assert "\r" in terminal, terminal
    assert (tmp_path / "d" / "report.json").exists()


def test_no_progress_line_in_a_pipe(tmp_path):
    run = subprocess.run(command(tmp_path / "d"), cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    for text in PROGRESS:
        assert text not in run.stderr, run.stderr
    assert (tmp_path / "d" / "report.json").exists()


def test_no_progress_line_with_quiet_on_a_terminal(tmp_path):
    for flag in ("-q", "--quiet"):
        status, stdout, terminal = run_with_stderr_on_a_terminal(command(tmp_path / flag, flag))
        assert status == 0, stdout + terminal
        for text in PROGRESS:
            assert text not in terminal, f"{flag}: {terminal!r}"
        assert (tmp_path / flag / "report.json").exists()

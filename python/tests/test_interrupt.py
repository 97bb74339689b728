"""Ctrl-C during a long call: the call stops within a moment and raises KeyboardInterrupt,
instead of running to its end first (the calls run without the GIL, so Python could not
act on the signal until they returned)."""

import os
import subprocess
import sys
import textwrap

# A dilation that runs for 7-15 s on the 2-core build machine, interrupted after 0.3 s;
# run in a child process so that the signal reaches only it.
_CHILD = textwrap.dedent("""
    import os, signal, sys, threading, time
    import numpy as np
    import vola
    rng = np.random.default_rng(1)
    tree = vola.build_from_voxels(rng.integers(0, 1024, (20000, 3)), 5)
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    try:
        tree.dilate(12)
        print("finished", time.monotonic() - start)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - start)
""")


def test_ctrl_c_stops_a_long_dilation():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    out = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, timeout=120, env=env)
    assert out.returncode == 0, out.stderr
    word, seconds = out.stdout.split()
    assert word == "interrupted", out.stdout
    assert float(seconds) < 4.0, out.stdout

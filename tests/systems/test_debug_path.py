"""The debugging path: with ``NUMBA_DISABLE_JIT=1`` every kernel runs as Python (no compiled
code), and a small scene runs through the same code to its closed form: the three-footed
stool at rest carries m g / 3 on each foot."""
import os
import subprocess
import sys

CODE = """
import numpy as np
from pydrake.systems.analysis import SimulatorConfig
from drake_dock.studies.small_scenes import G, stool
from drake_dock.systems.simulator import make_simulator
import numba
assert numba.config.DISABLE_JIT
sc = stool()
r = sc.params["foot_radius"]
sim = make_simulator(sc.system, SimulatorConfig(), lambda ctx: sc.set_state(
    ctx, (np.eye(3), np.array([0.0, 0.0, 0.2 + r])), (np.zeros(3), np.zeros(3))),
    witness_accuracy=1e-8)
sim.Initialize()
sim.AdvanceTo(0.02)
lam = sc.system.eval(sim.get_context()).lam_n
print(np.abs(lam - sc.params["mass"] * G / 3).max())
"""


def test_the_kernels_run_as_python_with_the_jit_disabled():
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert float(out.stdout.split()[-1]) < 1e-9

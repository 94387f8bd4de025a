import sys, time
import numpy as np
from lbmpy import LBMConfig, LBStencil, Stencil, Method
from lbmpy.lbstep import LatticeBoltzmannStep
import pystencils as ps

n = int(sys.argv[1]); threads = int(sys.argv[2])
cfg = LBMConfig(stencil=LBStencil(Stencil.D2Q9), method=Method.SRT, relaxation_rate=1/0.8, compressible=True)
step = LatticeBoltzmannStep(domain_size=(n, n), periodicity=(True, True), lbm_config=cfg,
                            optimization={'openmp': threads if threads > 1 else False, 'double_precision': True})
step.run(5)
steps = max(20, int(2e8 / (n * n)))
t = time.perf_counter(); step.run(steps); dt = time.perf_counter() - t
print(n, threads, round(n * n * steps / dt / 1e6, 1), steps)

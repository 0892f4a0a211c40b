"""flight-sysid's command line.

BLAS runs one thread per process unless the user's environment says otherwise: the matrices here
are small (tens to a few thousand rows), and OpenBLAS's idle threads spin. Measured on ``sysid fit``
of the 60 chapter 3 sweeps: 6.6 s wall and 6.0 s CPU with one thread, 7.2 s and 11.4 s with two.
Set before numpy loads (this package is imported first by the ``sysid`` command).
"""

import os as _os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_name, "1")

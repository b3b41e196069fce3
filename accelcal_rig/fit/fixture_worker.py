"""Imported first by the fork server of `fixture_pool`: one BLAS thread per worker, set before numpy is
loaded, then the fit's modules, so each worker forked from the server starts with them loaded."""

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_name] = "1"

import accelcal_rig.fit.campaign_fit  # noqa: E402,F401  (loaded once, in the server)

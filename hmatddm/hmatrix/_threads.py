"""One threadpoolctl controller for the process.

Building a controller (or calling ``threadpool_limits``) scans the loaded native
libraries, about 0.7 ms each time: a third of a small 2D run when it happened on every
GMRES call (measured on ref. Table 4.2). The controller is built once and reused.
"""
from threadpoolctl import ThreadpoolController

_CONTROLLER = []


def single_threaded_blas():
    """Context manager limiting BLAS/LAPACK to one thread."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0].limit(limits=1, user_api="blas")

"""hmatddm/compiled.py: the serial twin of a parallel function has a numba cache of its
own (issue 40: with a shared one, whichever compiled first was loaded for both)."""
import os
import subprocess
import sys
import textwrap

from conftest import child_environment

MODULE = textwrap.dedent('''
    import numpy as np
    from numba import njit, prange
    from hmatddm.compiled import serial_twin

    @njit(parallel=True, cache=True)
    def total(x):
        s = 0.0
        for i in prange(x.shape[0]):
            s += x[i]
        return s

    total_serial = serial_twin(total, cache=True)
''')


def _run(folder, code):
    environment = child_environment()
    environment["NUMBA_CACHE_DIR"] = str(folder / "cache")
    environment["PYTHONPATH"] = os.pathsep.join([str(folder), environment.get("PYTHONPATH", "")])
    result = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=environment, capture_output=True,
                            text=True, check=True)
    return result.stdout.split()


def test_a_serial_twin_compiled_first_does_not_stand_in_for_the_parallel_function(tmp_path):
    (tmp_path / "twins.py").write_text(MODULE)
    # the twin first: it compiles and fills the cache
    assert _run(tmp_path, """
        import numpy as np, twins
        print(twins.total_serial(np.ones(1000)), twins.total_serial.__qualname__)
    """) == ["1000.0", "total_serial"]
    # a new process: the parallel function loads its own code, which starts the threading
    # layer (it would not, had it loaded the twin's serial code)
    assert _run(tmp_path, """
        import numba, numpy as np, twins
        value = twins.total(np.ones(1000))
        try:
            numba.threading_layer()
            print(value, "parallel")
        except ValueError:
            print(value, "serial")
    """) == ["1000.0", "parallel"]

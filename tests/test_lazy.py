"""hmatddm._lazy: package attributes imported on first use (PEP 562). Each check runs in
a fresh interpreter, since this test process has long imported everything; no wall-clock
limit is set (a busy machine only makes it slower)."""
import subprocess
import sys

from conftest import child_environment


def _fresh(code):
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env=child_environment())
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


def test_importing_the_package_loads_no_engine_and_no_renderer():
    heavy = ("numba", "pyvista", "matplotlib", "scipy.sparse.linalg", "hmatddm.kernels", "hmatddm.hmatrix")
    loaded = _fresh(f"import sys, hmatddm; print(*[m for m in {heavy!r} if m in sys.modules])")
    assert loaded == []


def test_importing_the_aca_module_compiles_nothing_until_the_steps_are_asked_for():
    """Issue 18 item 7: the ACA steps are compiled on first use (``aca_steps()``), with
    their declared signatures, not when ``hmatddm.hmatrix.aca`` is imported."""
    out = _fresh("from hmatddm.hmatrix import aca\n"
                 "print(*[len(step.overloads) for step in aca.ACA_STEPS])\n"
                 "steps = aca.aca_steps()\n"
                 "print(*[len(step.overloads) for step in steps])\n"
                 "print(*[step.get_compile_result(kind.signature).signature == kind.signature\n"
                 "        for step, kind in zip(steps, aca.ACA_STEP_TYPES)])")
    assert out == ["0", "0", "0", "1", "1", "1", "True", "True", "True"]


def test_a_name_is_imported_on_first_access_and_then_bound():
    out = _fresh("import sys, hmatddm as hd\n"
                 "print('hmatddm.material' in sys.modules)\n"
                 "e = hd.Elastic\n"
                 "print('hmatddm.material' in sys.modules, 'Elastic' in vars(hd))")
    assert out == ["False", "True", "True"]


def test_an_export_wins_over_its_submodule_of_the_same_name():
    """Importing the module hmatddm.elasticity.solve must leave hmatddm.elasticity.solve
    (and hmatddm.solve) the function."""
    out = _fresh("import hmatddm as hd, importlib, types\n"
                 "f = hd.elasticity.solve\n"
                 "importlib.import_module('hmatddm.elasticity.solve')\n"
                 "print(isinstance(hd.elasticity.solve, types.ModuleType), hd.elasticity.solve is f, hd.solve is f)")
    assert out == ["False", "True", "True"]


def test_an_unknown_name_is_an_attribute_error():
    out = _fresh("import hmatddm as hd\n"
                 "try:\n    hd.no_such_name\nexcept AttributeError as e:\n    print('AttributeError')")
    assert out == ["AttributeError"]

"""An offscreen pyvista plotter (no window ever opens) and its PNG output: the render
context of a headless machine, and a clear error when there is none.
"""
import numpy as np

from ..errors import HmatddmError
from ..io import atomic_output


def offscreen_pyvista():
    """pyvista, switched to offscreen rendering."""
    try:
        import pyvista
    except ImportError as error:  # pragma: no cover - pyvista is a dependency
        raise HmatddmError(f"snapshots need pyvista, which could not be imported: {error}") from error
    pyvista.OFF_SCREEN = True
    return pyvista


def no_render_context(cause):
    return HmatddmError(
        "pyvista could not create an offscreen render context, so no snapshot was written "
        f"({type(cause).__name__}: {cause}). On a headless machine use a VTK build with EGL or "
        "OSMesa (e.g. the 'vtk-osmesa' wheel) or run under a virtual display (xvfb-run)."
    )


def new_plotter(pyvista, window_size):
    """An offscreen plotter on a white background.

    VTK's warning while it falls back from X to EGL/OSMesa on a headless machine
    ("bad X server connection") is silenced while the plotter is made; errors still
    show.
    """
    from vtkmodules.vtkCommonCore import vtkLogger

    verbosity = vtkLogger.GetCurrentVerbosityCutoff()
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)
    try:
        plotter = pyvista.Plotter(off_screen=True, window_size=list(window_size),
                                  theme=pyvista.themes.DocumentTheme())
    except Exception as error:
        raise no_render_context(error) from error
    finally:
        vtkLogger.SetStderrVerbosity(verbosity)
    if not supports_opengl(plotter):
        plotter.close()
        raise no_render_context(RuntimeError("the render window reports no OpenGL support"))
    return plotter


def supports_opengl(plotter):
    """Whether VTK can make an OpenGL context for this plotter (True when VTK cannot tell)."""
    supports = getattr(plotter.render_window, "SupportsOpenGL", None)
    if supports is None:
        return True
    try:
        return bool(supports())
    except Exception:
        return False


def save_png(image, path):
    """Write an (H, W, 3|4) uint8 image as PNG, atomically."""
    from PIL import Image

    with atomic_output(path) as temporary:
        Image.fromarray(np.ascontiguousarray(image)).save(temporary, format="PNG")
    return path


def screenshot(plotter, window_size):
    try:
        image = plotter.screenshot(return_img=True, window_size=list(window_size))
    except Exception as error:
        raise no_render_context(error) from error
    if image is None or image.size == 0 or int(np.max(image)) == 0:
        # A white-background scene that renders all black means no working GL context.
        raise no_render_context(RuntimeError("the rendered image is empty (all black)"))
    return image

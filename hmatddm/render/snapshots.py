"""Offscreen PNG snapshots of fractures with pyvista (no window ever opens).

:func:`snapshot` draws one view of a mesh:

* elements coloured by their ``opening`` (metres in, millimetres on the scalar bar);
* with a per-element ``state``: hydraulic-fracture elements (0) coloured by opening,
  intact natural-fracture elements (1) as a light grey wireframe (they are stress
  targets, not unknowns, so their opening means nothing), failed natural-fracture
  elements (2) coloured by opening and outlined in red (each failed patch, and
  every element border on small meshes);
* with ``slip`` vectors: arrows at the elements that slip (magnitude above
  ``1e-3`` of the largest), their length proportional to the slip;
* a legend at the bottom names the natural-fracture states and the slip arrows; the
  opening colour bar runs from 0 (negative openings of closed elements are drawn as 0,
  and the bar's title says so with the smallest value, :func:`opening_colour_range`);
* a plan view frames the fractures left of the colour bar, under the title and above
  the legend (:func:`plan_frame`), with a round length scale in the lower left corner;
* ``view="plan"`` looks down ``-z`` (map view, parallel projection),
  ``view="oblique"`` is an isometric perspective. A :class:`~hmatddm.mesh.Mesh2D` is
  always drawn in the ``xy``-plane seen from ``+z``: each element as a band across its
  segment as wide as its opening, exaggerated so that the widest is 4 % of the mesh
  diagonal (the factor is written under the title), over a thin centre line.
* the plan view of a 3D mesh of (mostly) vertical fractures, which looking down ``-z``
  would see edge on, draws each vertical element as its horizontal trace (a line, as
  in the DFN maps of ref. Figs 6.10-6.14): the elements of one column (same fracture,
  same trace, stacked over the height) merge into one line coloured by the LARGEST
  opening over the height; intact natural fractures are thin grey lines, failed or
  activated natural ones are coloured by opening with a red border (as in 2D); slip
  arrows show the horizontal (strike-slip) part of the slip. The few non-vertical
  elements of such a mesh are drawn as surfaces underneath (:func:`plan_traces`).

:func:`snapshots` writes both views of one state.
"""
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.vtk import cells_of
from ..mesh import Mesh2D, Mesh3D
from .layout import (BAR_LEFT, FAILED_COLOR, FAILED_NATURAL, INTACT_COLOR, INTACT_NATURAL, MAX_ELEMENTS_WITH_EDGES,
                     MAX_SLIP_ARROWS, OPENING_COLORMAP, PLAIN_SURFACE_COLOR, PLAN_STYLES, SCALE_Y, SLIP_ARROW_COLOR,
                     SLIP_VISIBLE_FRACTION, VERTICAL_NORMAL_Z, VIEWS, check_fields, check_mesh_type, check_window_size,
                     mesh_diagonal, length_text, plan_extent, slip_shown, is_mostly_vertical, legend_labels,
                     opening_colour_range, plan_frame, plan_scale_bar, plan_traces, slip_arrow_length,
                     vertical_elements, Curve, check_curves, dashes, plan_ticks, opening_ribbon, ribbon_text)
from .offscreen import new_plotter, offscreen_pyvista, save_png, screenshot


# ---------------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------------


def element_geometry(mesh):
    """The elements as pyvista ``PolyData``, one cell per element in mesh order:
    quads for a Mesh3D, line segments at ``z = 0`` for a Mesh2D (the cells the
    ``.vtu`` files hold, :func:`hmatddm.io.vtk.cells_of`)."""
    pyvista = offscreen_pyvista()
    points, connectivity, _ = cells_of(mesh)
    n_elements, nodes_per_cell = connectivity.shape
    cells = np.column_stack([np.full(n_elements, nodes_per_cell), connectivity]).reshape(-1)
    if isinstance(mesh, Mesh3D):
        return pyvista.PolyData(points, faces=cells)
    return pyvista.PolyData(points, lines=cells)


def _part(mesh, indices, lift=0.0):
    """:func:`element_geometry` of the elements ``indices`` only, moved up by ``lift``
    (m, along ``z``)."""
    part = element_geometry(mesh.subset(indices))
    return part.translate((0.0, 0.0, lift), inplace=False) if lift else part


# ---------------------------------------------------------------------------------
# Layers
# ---------------------------------------------------------------------------------


def _line_width(coloured=True):
    """Pixels of a 2D segment (coloured) or of a wireframe edge."""
    return 6 if coloured else 2


def _ribbon(mesh, indices, opening, lift=0.0):
    """The 2D elements ``indices`` as the band of :func:`opening_ribbon` (quads at ``z =
    lift``) and its exaggeration, or ``(None, None)`` when none of them is open."""
    pyvista = offscreen_pyvista()
    points, quads, exaggeration = opening_ribbon(mesh.subset(indices), opening[indices], mesh_diagonal(mesh))
    if points is None:
        return None, None
    points = np.column_stack([points, np.full(len(points), float(lift))])
    faces = np.column_stack([np.full(len(quads), 4), quads]).reshape(-1)
    return pyvista.PolyData(points, faces=faces), exaggeration


def _add_coloured(plotter, mesh, indices, opening, lift=0.0, clim=None):
    """Hydraulic and failed elements: coloured by opening (mm; colour range ``clim``,
    default that of these elements, :func:`opening_colour_range`) or a plain colour.

    2D (and the traces of a 3D plan view): each element is drawn as a band across its
    segment as wide as its opening times an exaggeration (:func:`opening_ribbon`), over a
    thin coloured centre line that keeps closed elements in sight. Returns the
    exaggeration (None without a band)."""
    if indices.size == 0:
        return None
    part = _part(mesh, indices, lift)
    is_2d = isinstance(mesh, Mesh2D)
    style = dict(line_width=_line_width(), render_lines_as_tubes=True) if is_2d else dict(
        show_edges=mesh.n_elements <= MAX_ELEMENTS_WITH_EDGES, edge_color="dimgrey")
    if opening is None:
        plotter.add_mesh(part, color=PLAIN_SURFACE_COLOR, **style)
        return None
    opening_mm = 1e3 * opening
    part.cell_data["opening (mm)"] = opening_mm[indices]
    if clim is None:
        clim = opening_colour_range(opening_mm[indices])
    limits, title = clim
    colours = dict(scalars="opening (mm)", cmap=OPENING_COLORMAP, clim=limits)
    exaggeration = None
    if is_2d:
        band, exaggeration = _ribbon(mesh, indices, opening, lift)
        style.update(line_width=_line_width(coloured=False), render_lines_as_tubes=False)
        if band is not None:
            band.cell_data["opening (mm)"] = opening_mm[indices]
            plotter.add_mesh(band, show_scalar_bar=False, lighting=False, **colours)
    plotter.add_mesh(part, scalar_bar_args=dict(title=title, vertical=True, fmt="%.3g", position_x=BAR_LEFT,
                                                position_y=0.15, height=0.7, width=0.08),
                     **colours, **style)
    return exaggeration


def _add_intact(plotter, mesh, indices, lift=0.0):
    """Intact natural fractures: a light grey wireframe."""
    if indices.size == 0:
        return
    part = _part(mesh, indices, lift)
    plotter.add_mesh(part, style="wireframe", color=INTACT_COLOR, line_width=_line_width(coloured=False))


def _region_boundary(mesh, indices):
    """Outer edges of the patch made of the cells ``indices`` (corners merged)."""
    patch = _part(mesh, indices)
    patch = patch.clean(tolerance=1e-9 * mesh_diagonal(mesh), absolute=True)
    return patch.extract_feature_edges(boundary_edges=True, non_manifold_edges=True,
                                       feature_edges=False, manifold_edges=False)


def _add_failed_outline(plotter, mesh, indices, lift=0.0):
    """Failed natural-fracture elements: outlined in red.

    3D: a thick red line around each failed patch, plus thin red borders of every
    failed element on meshes small enough for element borders to stay readable.
    2D: the red line is put behind the coloured one (seen from ``+z``) and drawn
    wider, so it shows as a red border of the coloured segment. It sits a tenth of the
    mesh diagonal lower: lines drawn as tubes have a depth of about their width, and a
    closer red tube would cover the coloured one (the parallel projection of a plan
    view does not move it on screen).
    """
    if indices.size == 0:
        return
    if isinstance(mesh, Mesh2D):
        part = _part(mesh, indices, lift - 0.1 * mesh_diagonal(mesh))
        # flat and unlit: the visible rim of a lit tube is shaded to dark red
        plotter.add_mesh(part, color=FAILED_COLOR, line_width=2 * _line_width(), lighting=False)
        return
    if mesh.n_elements <= MAX_ELEMENTS_WITH_EDGES:
        plotter.add_mesh(_part(mesh, indices), style="wireframe", color=FAILED_COLOR, line_width=1)
    plotter.add_mesh(_region_boundary(mesh, indices), color=FAILED_COLOR, line_width=4)


def _add_slip_arrows(plotter, mesh, slip, lift=0.0):
    """Arrows centred on the slipping elements (moved up by ``lift``), length
    proportional to ``|slip|`` (on at most ``MAX_SLIP_ARROWS`` of them, evenly thinned
    in element order)."""
    pyvista = offscreen_pyvista()
    magnitude = np.linalg.norm(slip, axis=1)
    largest = float(np.max(magnitude))
    if largest <= 0.0:
        return
    slipping = np.flatnonzero(magnitude > SLIP_VISIBLE_FRACTION * largest)
    shown = slipping[::max(1, -(-slipping.size // MAX_SLIP_ARROWS))]
    centers = mesh.centers[shown]
    vectors = slip[shown]
    if isinstance(mesh, Mesh2D):
        centers = np.column_stack([centers, np.full(len(shown), float(lift))])
        vectors = np.column_stack([vectors, np.zeros(len(shown))])
    points = pyvista.PolyData(centers)
    points["slip"] = vectors
    points["slip magnitude"] = magnitude[shown]
    arrow = pyvista.Arrow(start=(-0.5, 0.0, 0.0), direction=(1.0, 0.0, 0.0), tip_length=0.35,
                          tip_radius=0.18, shaft_radius=0.07, scale=1.0)
    length = slip_arrow_length(mesh, slipping, len(shown))
    arrows = points.glyph(orient="slip", scale="slip magnitude", factor=length / largest, geom=arrow)
    plotter.add_mesh(arrows, color=SLIP_ARROW_COLOR)


def _add_curves(plotter, mesh, curves):
    """Lines over the fractures (fronts): each :class:`Curve`'s points joined, dashed ones
    as dashes of about 1.5% of the mesh diagonal, lifted above every element (a plan view
    looks down ``-z``)."""
    pyvista = offscreen_pyvista()
    lift = (float(np.max(mesh.corners()[..., 2])) if isinstance(mesh, Mesh3D) else 0.0) + 0.3 * mesh_diagonal(mesh)
    for curve in curves:
        points = np.asarray(curve.points, dtype=float)
        if points.shape[1] == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        points = points + np.array([0.0, 0.0, lift])
        if curve.pairs:
            plotter.add_mesh(pyvista.line_segments_from_points(points), color=curve.colour, line_width=curve.width)
            continue
        pieces = [points] if not curve.dashed else dashes(points, 0.015 * mesh_diagonal(mesh))
        for piece in pieces:
            if len(piece) >= 2:
                plotter.add_mesh(pyvista.lines_from_points(piece), color=curve.colour, line_width=curve.width)


def _add_legend(plotter, state, slip_shown=False, curves=()):
    """The legend at the bottom, between the length scale and the colour bar, below the
    fractures in a plan view (:func:`plan_frame`)."""
    labels = legend_labels(state, slip_shown) + [[curve.label, curve.colour] for curve in curves if curve.label]
    if labels:
        plotter.add_legend(labels=labels, bcolor="white", face="rectangle", loc="lower center",
                           size=(0.4, 0.028 * len(labels) + 0.008))


def _set_view(plotter, mesh, view):
    """Oblique: isometric, framing every actor (plan views: :func:`_frame_plan`)."""
    plotter.view_isometric()
    plotter.reset_camera()


def _frame_plan(plotter, mesh, window_size, colour_bar, title, interfaces=()):
    """Look down ``-z`` (parallel projection) with the fractures inside :data:`PLAN_BOX`,
    and draw a length scale under them (and, in a 2D section, the layer ``interfaces``
    that cross the box as grey lines across it)."""
    pyvista = offscreen_pyvista()
    extent = plan_extent(mesh)
    centre_x, centre_y, scale, box = plan_frame(extent, window_size, colour_bar, title)
    aspect = window_size[0] / window_size[1]
    z_top = float(np.max(mesh.corners()[..., 2])) if isinstance(mesh, Mesh3D) else 0.0
    diagonal = mesh_diagonal(mesh)
    x_left = centre_x + (box[0] - 0.5) * 2.0 * scale * aspect
    x_right = centre_x + (box[1] - 0.5) * 2.0 * scale * aspect
    y_low, y_high = (centre_y + (edge - 0.5) * 2.0 * scale for edge in (box[2], box[3]))
    shown = [height for height in interfaces if y_low <= height <= y_high]
    for height in shown:
        plotter.add_mesh(pyvista.Line((x_left, height, -1e-3 * diagonal), (x_right, height, -1e-3 * diagonal)),
                         color="grey", line_width=2)
    if shown:
        plotter.add_text("grey lines: layer interfaces", position=(int(0.3 * window_size[0]),
                                                                    int((SCALE_Y - 0.02) * window_size[1])),
                         font_size=10, color="grey")
    # the length scale: a black bar from the left edge of the box, at SCALE_Y
    length = plan_scale_bar(extent, window_size, colour_bar, title)
    x0 = centre_x + (box[0] - 0.5) * 2.0 * scale * aspect
    y0 = centre_y + (SCALE_Y - 0.5) * 2.0 * scale
    lift = z_top + 0.5 * diagonal
    plotter.add_mesh(pyvista.Line((x0, y0, lift), (x0 + length, y0, lift)), color="black", line_width=4)
    right_end = box[0] + length / (2.0 * scale * aspect)
    plotter.add_text(length_text(length), position=(int((right_end + 0.01) * window_size[0]),
                                                     int((SCALE_Y - 0.02) * window_size[1])),
                     font_size=10, color="black")
    _plan_axes(plotter, (x_left, x_right, y_low, y_high), box, window_size, lift, diagonal)
    plotter.view_xy()  # the camera pyvista frames (its distance keeps the lighting), moved over the box
    plotter.enable_parallel_projection()
    plotter.reset_camera()
    camera = plotter.camera
    focal, position = camera.focal_point, camera.position
    camera.focal_point = (centre_x, centre_y, focal[2])
    camera.position = (centre_x, centre_y, position[2])
    camera.parallel_scale = scale
    plotter.reset_camera_clipping_range()


def _plan_axes(plotter, limits, box, window_size, lift, diagonal):
    """Axes in metres round the plot box of a plan view: ticks at round coordinates along
    its lower and left edges (x to the right, y up), labelled below and inside."""
    pyvista = offscreen_pyvista()
    x_left, x_right, y_low, y_high = limits
    width, height = window_size
    tick = 0.012 * max(x_right - x_left, y_high - y_low)
    segments = []
    for x in plan_ticks(x_left, x_right):
        segments += [(x, y_low, lift), (x, y_low + tick, lift)]
        fraction = box[0] + (x - x_left) / (x_right - x_left) * (box[1] - box[0])
        plotter.add_text(f"{x:g}", position=(int(fraction * width) - 8, int((box[2] - 0.035) * height)),
                         font_size=9, color="dimgrey")
    for y in plan_ticks(y_low, y_high):
        segments += [(x_left, y, lift), (x_left + tick, y, lift)]
        fraction = box[2] + (y - y_low) / (y_high - y_low) * (box[3] - box[2])
        plotter.add_text(f"{y:g}", position=(int(box[0] * width) + 12, int(fraction * height) - 7),
                         font_size=9, color="dimgrey")
    segments += [(x_left, y_low, lift), (x_right, y_low, lift), (x_left, y_low, lift), (x_left, y_high, lift)]
    plotter.add_mesh(pyvista.line_segments_from_points(np.array(segments, dtype=float)), color="dimgrey",
                     line_width=1)
    plotter.add_text("x (m)", position=(int(box[1] * width) - 40, int((box[2] - 0.035) * height)), font_size=9,
                     color="dimgrey")
    plotter.add_text("y (m)", position=(int(box[0] * width) + 12, int(box[3] * height) + 4), font_size=9,
                     color="dimgrey")


def _add_interface_planes(plotter, mesh, interfaces):
    """The layer interfaces ``z = d`` of a 3D side (oblique) view: translucent grey planes over
    the fractures' horizontal extent (padded by a fifth), those within a mesh diagonal of
    the fractures, named in a line of text."""
    pyvista = offscreen_pyvista()
    corners = mesh.corners().reshape(-1, 3)
    low, high = corners.min(axis=0), corners.max(axis=0)
    diagonal = mesh_diagonal(mesh)
    span = np.maximum(high[:2] - low[:2], 0.2 * diagonal) * 1.4
    centre = 0.5 * (low[:2] + high[:2])
    shown = [d for d in interfaces if low[2] - diagonal <= d <= high[2] + diagonal]
    for height in shown:
        plane = pyvista.Plane(center=(centre[0], centre[1], height), direction=(0.0, 0.0, 1.0), i_size=span[0],
                              j_size=span[1], i_resolution=1, j_resolution=1)
        plotter.add_mesh(plane, color="grey", opacity=0.25, show_edges=True, edge_color="dimgrey")
    if shown:
        plotter.add_text("grey planes: layer interfaces (" + ", ".join(f"z = {d:g} m" for d in shown) + ")",
                         position="lower_left", font_size=10, color="dimgrey")


def _draw(plotter, mesh, opening, state, slip, curves=()):
    """Every element as itself; returns the exaggeration of a 2D opening band, or None."""
    every = np.arange(mesh.n_elements)
    if state is None:
        exaggeration = _add_coloured(plotter, mesh, every, opening)
    else:
        exaggeration = _add_coloured(plotter, mesh, every[state != INTACT_NATURAL], opening)
        _add_intact(plotter, mesh, every[state == INTACT_NATURAL])
        _add_failed_outline(plotter, mesh, every[state == FAILED_NATURAL])
    _add_legend(plotter, state, slip_shown(slip), curves)
    if slip is not None:
        _add_slip_arrows(plotter, mesh, slip)
    _add_curves(plotter, mesh, curves)
    return exaggeration


# ---------------------------------------------------------------------------------
# Plan view of vertical fractures: traces
# ---------------------------------------------------------------------------------


def _draw_plan_traces(plotter, mesh, opening, state, slip, curves=()):
    """Plan view of a mostly vertical Mesh3D: traces of the vertical elements on top,
    the non-vertical elements as surfaces (as :func:`_draw`) underneath. Returns the
    exaggeration of the traces' opening band, or None."""
    vertical = vertical_elements(mesh)
    traces, line_opening, line_state, line_slip, _ = plan_traces(mesh, opening, state, slip)
    others = np.flatnonzero(~vertical)
    every_state = np.zeros(mesh.n_elements, dtype=np.int64) if state is None else state
    coloured = every_state != INTACT_NATURAL
    clim = None
    if opening is not None and np.any(coloured):
        clim = opening_colour_range(1e3 * opening[coloured])
    # surfaces of the non-vertical elements at their own height ...
    if others.size:
        if state is None:
            _add_coloured(plotter, mesh, others, opening, clim=clim)
        else:
            _add_coloured(plotter, mesh, others[state[others] != INTACT_NATURAL], opening, clim=clim)
            _add_intact(plotter, mesh, others[state[others] == INTACT_NATURAL])
            _add_failed_outline(plotter, mesh, others[state[others] == FAILED_NATURAL])
        if slip is not None and np.any(slip[others]):
            _add_slip_arrows(plotter, mesh.subset(others), slip[others])
    # ... and the traces above every element (the camera looks down -z), with room
    # for their red borders (:func:`_add_failed_outline`) in between
    lift = float(np.max(mesh.corners()[..., 2])) + 0.2 * mesh_diagonal(mesh)
    lines = np.arange(traces.n_elements)
    if line_state is None:
        exaggeration = _add_coloured(plotter, traces, lines, line_opening, lift=lift, clim=clim)
    else:
        exaggeration = _add_coloured(plotter, traces, lines[line_state != INTACT_NATURAL], line_opening, lift=lift,
                                     clim=clim)
        _add_intact(plotter, traces, lines[line_state == INTACT_NATURAL], lift=lift)
        _add_failed_outline(plotter, traces, lines[line_state == FAILED_NATURAL], lift=lift)
    _add_legend(plotter, state, slip_shown(line_slip) or (slip is not None and slip_shown(slip[others])), curves)
    if line_slip is not None and np.any(line_slip):
        _add_slip_arrows(plotter, traces, line_slip, lift=lift)
    _add_curves(plotter, mesh, curves)
    return exaggeration


# ---------------------------------------------------------------------------------
# Output
# ---------------------------------------------------------------------------------

def snapshot(mesh, path, opening=None, state=None, slip=None, view="oblique", title=None,
             window_size=(1200, 900), plan_style="auto", interfaces=(), curves=()):
    """Render one offscreen PNG of the fractures.

    Parameters
    ----------
    mesh : Mesh2D or Mesh3D
    path : str or Path
        Output PNG (folder created if missing; written atomically).
    opening : (N,) array, optional
        Opening ``w = DD . n`` in metres; shown in millimetres on the scalar bar.
    state : (N,) int array, optional
        0 hydraulic fracture (coloured by opening), 1 intact natural fracture (light
        grey wireframe), 2 failed natural fracture (coloured by opening, red outline).
    slip : (N, d) array, optional
        Slip vectors (global frame, m); arrows at elements slipping more than
        ``1e-3`` of the largest slip, length proportional to the slip (the largest
        arrow spans a few elements, 3-12% of the mesh diagonal).
    view : {"plan", "oblique"}
        ``plan`` looks down ``-z`` (parallel projection), ``oblique`` is isometric.
        Ignored for a Mesh2D (always seen from ``+z``).
    plan_style : {"auto", "traces", "surfaces"}
        How a plan view draws a Mesh3D. ``traces``: each vertical element as its
        horizontal trace, one line per column coloured by the largest opening over the
        height (:func:`plan_traces`), non-vertical elements as surfaces underneath;
        ``surfaces``: every element as a surface (vertical ones are then edge on and
        invisible); ``auto``: traces when vertical elements hold at least half the
        area (:func:`is_mostly_vertical`), else surfaces. Ignored for other views and
        for a Mesh2D.
    title : str, optional
        Text at the top of the image.
    window_size : (width, height)
        Image size in pixels.
    interfaces : sequence of float, optional
        Heights (m, the vertical coordinate, docs/conventions.md §3) of layer interfaces,
        drawn in a 2D vertical section as grey lines across the picture and in the
        oblique view of a Mesh3D as translucent horizontal planes (not in its plan view,
        which looks down on them).
    curves : sequence of Curve, optional
        Lines drawn over the fractures and named in the legend (the tracked front, the
        closed-form front dashed), points in metres (2D: x, y).

    Returns
    -------
    Path

    Raises
    ------
    InputError
        Fields of the wrong shape or with NaN/inf, a ``state`` outside {0, 1, 2}, an
        unknown ``view`` or ``plan_style``, ``plan_style="traces"`` for a mesh without
        vertical elements.
    HmatddmError
        pyvista cannot render offscreen on this machine.
    """
    check_mesh_type(mesh)
    if view not in VIEWS:
        raise InputError(f"view must be one of {VIEWS}, got {view!r}")
    if plan_style not in PLAN_STYLES:
        raise InputError(f"plan_style must be one of {PLAN_STYLES}, got {plan_style!r}")
    window_size = check_window_size(window_size)
    opening, state, slip = check_fields(mesh, opening, state, slip)
    interfaces = np.asarray(interfaces if interfaces is not None else (), dtype=float).ravel()
    if not np.all(np.isfinite(interfaces)):
        raise InputError("interfaces must be finite heights (m)")
    traces = view == "plan" and isinstance(mesh, Mesh3D) and (
        plan_style == "traces" or (plan_style == "auto" and is_mostly_vertical(mesh)))
    if traces and not np.any(vertical_elements(mesh)):
        raise InputError(f"plan_style='traces' needs vertical elements (|n_z| <= {VERTICAL_NORMAL_Z}); "
                         "this mesh has none")
    pyvista = offscreen_pyvista()
    plotter = new_plotter(pyvista, window_size)
    try:
        curves = check_curves(curves, mesh.dim)
        if traces:
            exaggeration = _draw_plan_traces(plotter, mesh, opening, state, slip, curves)
        else:
            exaggeration = _draw(plotter, mesh, opening, state, slip, curves)
        if title is not None:
            plotter.add_text(str(title), position="upper_edge", font_size=12)
        if exaggeration is not None:  # in the lower left corner, under the length scale
            plotter.add_text(ribbon_text(exaggeration), position=(int(0.02 * window_size[0]),
                                                                  int(0.012 * window_size[1])),
                             font_size=9, color="dimgrey")
        if view == "oblique" and isinstance(mesh, Mesh3D):
            plotter.add_axes()  # a plan view has x to the right and y up, and a length scale instead
            _add_interface_planes(plotter, mesh, interfaces)
        if view == "plan" or isinstance(mesh, Mesh2D):
            _frame_plan(plotter, mesh, window_size, colour_bar=opening is not None, title=title is not None,
                        interfaces=interfaces if isinstance(mesh, Mesh2D) else ())
        else:
            _set_view(plotter, mesh, view)
        image = screenshot(plotter, window_size)
    finally:
        plotter.close()
    return save_png(image, Path(path))


def snapshots(mesh, folder, stem, **fields):
    """Write ``folder/<stem>_plan.png`` and ``folder/<stem>_oblique.png``.

    ``fields`` are passed to :func:`snapshot` (``opening``, ``state``, ``slip``,
    ``title``, ``window_size``, ``plan_style``). A Mesh2D has one view only, so only the
    plan image is written; a 3D plan view of vertical fractures draws their traces. Returns the list of written paths (plan first).
    """
    if "view" in fields:
        raise InputError("snapshots writes every view; call snapshot(..., view=...) for one view")
    folder = Path(folder)
    views = ("plan",) if isinstance(mesh, Mesh2D) else VIEWS
    return [snapshot(mesh, folder / f"{stem}_{view}.png", view=view, **fields) for view in views]


__all__ = ["snapshot", "snapshots", "element_geometry", "Curve"]

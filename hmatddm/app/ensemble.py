"""Ensembles of seeded realizations on Dask (docs/conventions.md §8; ref. Fig. 6.9).

:func:`sweep` runs a task for every point of a parameter grid and every seed on a Dask
cluster: a ``LocalCluster`` by default, or the scheduler at ``scheduler`` (an address
such as ``"tcp://10.0.0.5:8786"``). Tasks are plain functions of a parameter dict
and a seed that return a dict of numbers, so they pickle cheaply and any worker can
run them; results come back in a deterministic order (grid order, then seed).

The built-in task :func:`intersection_frequency_task` generates a natural-fracture
network (ref. Sec. 6.2) and measures the frequency of intersections along the y
axis per metre (ref. Fig. 6.9); :func:`summarize` reduces the realizations to mean,
minimum and maximum per grid point, the error bars of the reference's figure.

Dask is an optional dependency: ``pip install "hmatddm[dask]"``.
"""
import itertools

import numpy as np

from .._validation import positive_int
from ..errors import InputError


def intersection_frequency_task(parameters, seed):
    """Frequency of intersections along the y axis (1/m) of one seeded realization.

    ``parameters``: keys of :class:`hmatddm.network.NetworkSpec` (e.g. ``density``,
    ``length_exponent``, ``region``); the reference's Table 6.1 values are the defaults.
    """
    from ..network import generate_network, intersection_frequency

    network = generate_network(_network_spec(parameters, seed))
    return {"intersection_frequency": float(intersection_frequency(network)),
            "n_fractures": int(network.n_fractures)}


def _network_spec(parameters, seed):
    """The :class:`hmatddm.network.NetworkSpec` of one grid point (Table 6.1 defaults);
    InputError naming the parameter when a value is out of range."""
    from ..network import NetworkSpec

    spec_args = dict(region=(-50.0, 50.0, -50.0, 50.0), density=0.05, length_exponent=2.0, l_min=1.0,
                     l_max=30.0, mean_azimuths_deg=(45.0,), kappas=(5.0,))
    spec_args.update(parameters)
    try:
        return NetworkSpec(seed=int(seed), **spec_args)
    except TypeError as error:  # an unknown parameter name
        raise InputError(f"grid parameter not understood by NetworkSpec: {error}") from None


def parameter_grid(**axes):
    """List of dicts, one per combination of the given value lists (in order)."""
    names = list(axes)
    for name in names:
        if not isinstance(axes[name], (list, tuple)) or not axes[name]:
            raise InputError(f"grid axis {name!r} must be a non-empty list of values")
    return [dict(zip(names, values)) for values in itertools.product(*(axes[n] for n in names))]


def sweep(grid, realizations=10, task=intersection_frequency_task, scheduler=None, n_workers=None,
          first_seed=0):
    """Run ``task(parameters, seed)`` for every grid point and ``realizations`` seeds.

    Returns a list of dicts ``{**parameters, "seed": s, **task_result}`` in grid order,
    then seed order. ``scheduler``: a Dask scheduler address; ``None`` starts a local
    cluster with ``n_workers`` processes (default: the CPU count), closed afterwards.
    """
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - depends on the installation
        raise InputError('sweep needs Dask: pip install "hmatddm[dask]"') from None
    grid = list(grid)
    if not grid or not all(isinstance(point, dict) for point in grid):
        raise InputError("grid must be a non-empty list of parameter dicts")
    realizations = positive_int("realizations", realizations)
    if task is intersection_frequency_task:  # refuse bad values here, not in a worker's traceback
        for point in grid:
            _network_spec(point, first_seed)
    jobs = [(point, first_seed + k) for point in grid for k in range(realizations)]
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        client = Client(scheduler)
    try:
        futures = client.map(task, [p for p, _ in jobs], [s for _, s in jobs], pure=False)
        results = client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return [{**point, "seed": seed, **result} for (point, seed), result in zip(jobs, results)]


def summarize(rows, key="intersection_frequency", results=("n_fractures",)):
    """Mean, min, max and count of ``key`` per parameter combination (ref. Fig. 6.9).

    Rows are grouped by every field except ``seed``, ``key`` and the other task
    ``results``.
    """
    skip = {"seed", key, *results}
    groups = {}
    for row in rows:
        params = tuple((k, tuple(v) if isinstance(v, list) else v) for k, v in row.items() if k not in skip)
        groups.setdefault(params, []).append(row[key])
    table = []
    for params, values in groups.items():
        values = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(values)):
            raise InputError(f"{key} has non-finite values for {dict(params)}")
        table.append({**dict(params), "mean": float(values.mean()), "min": float(values.min()),
                      "max": float(values.max()), "count": int(values.size)})
    return table


def format_table(table, key="intersection frequency (1/m)"):
    """Markdown table of :func:`summarize` output."""
    if not table:
        return ""
    names = [k for k in table[0] if k not in ("mean", "min", "max", "count")]
    lines = ["| " + " | ".join(names) + f" | {key} mean | min | max | n |",
             "|" + "---|" * (len(names) + 4)]
    for row in table:
        cells = [str(row[n]) for n in names]
        lines.append("| " + " | ".join(cells) + f" | {row['mean']:.4f} | {row['min']:.4f} | {row['max']:.4f} "
                     f"| {row['count']} |")
    return "\n".join(lines)


__all__ = ["sweep", "parameter_grid", "summarize", "format_table", "intersection_frequency_task"]

"""The ``hmatddm`` command line.

Every scene is checked whole (values, meshes, clusters, collocation points on edges, size)
before numba or the engine load, so refusals come within a second. The command sets
``OMP_WAIT_POLICY=PASSIVE`` (unless set) before numba starts its threads.

    hmatddm run [SCENE] [--out DIR]   run a scene (embedded name or .toml file; default: "default")
    hmatddm scenes [NAME]             list the embedded scenes, or print one as TOML
    hmatddm validate [--json]         closed-form checks as a table of error and time
    hmatddm bench [--quick] [--json]  H-matrix against dense: build time, memory, matvec time, error
    hmatddm render DIR [--movie]      snapshots, profiles and history plot of a finished or partial run
    hmatddm sweep [--realizations N]  natural-fracture network ensembles on Dask (ref. Fig. 6.9)
    hmatddm microseismic DIR          event catalogue (events.csv) and map of a finished run (ref. Ch. 7)

Exit codes: 0 ok, 1 a check failed (validate), 2 bad input (also a scene over
numerics.max_elements or the memory available, and a run whose growth would pass
numerics.max_elements: it stops with the last step checkpointed), 3 did not converge,
4 an output could not be written (the disk is full or the folder is not writable; every
finished step is checkpointed, so free space and continue with --resume),
130 interrupted (Ctrl-C; a run can be continued with --resume).
"""
import argparse
import json
import os
import shlex
import sys
from pathlib import Path

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_NOT_CONVERGED, EXIT_OUTPUT, EXIT_INTERRUPTED = 0, 1, 2, 3, 4, 130
DEFAULT_SCENE = "default"
DEFAULT_OUT_ROOT = "hmatddm-runs"


def _say(args, text, stream=None):
    if not getattr(args, "quiet", False):
        print(text, file=stream or sys.stdout)


# ---------------------------------------------------------------------------------
# validate
# ---------------------------------------------------------------------------------

def _validate(args):
    from .validate import format_table, run_checks

    rows = run_checks(stream=None if args.quiet else sys.stderr)
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print(format_table(rows))
    return EXIT_OK if all(r["passed"] for r in rows) else EXIT_FAILED


# ---------------------------------------------------------------------------------
# scenes
# ---------------------------------------------------------------------------------

def _scenes(args):
    from ..scene import embedded_names, embedded_scenes, embedded_text

    if args.name:
        sys.stdout.write(embedded_text(args.name))
        return EXIT_OK
    scenes = embedded_scenes()
    if args.json:
        print(json.dumps(scenes, indent=2))
        return EXIT_OK
    width = max(len(name) for name in embedded_names())
    for name, description in scenes.items():
        print(f"{name:<{width}}  {description}")
    return EXIT_OK


# ---------------------------------------------------------------------------------
# run
# ---------------------------------------------------------------------------------

def _resume_command(args, out):
    parts = ["hmatddm", "run", "--out", str(out), "--resume"]
    return " ".join(shlex.quote(p) for p in parts)


def _load_run_scene(args):
    """The scene to run and the output folder."""
    from ..scene import load_scene

    overrides = list(args.set or [])
    if args.backend:
        overrides.append(f'numerics.backend="{args.backend}"')
    stored = None
    if args.scene is None and args.resume and args.out:
        from .runner import SCENE_FILE

        stored = Path(args.out) / SCENE_FILE
    if stored is not None and stored.is_file():
        scene = load_scene(str(stored), overrides=overrides)  # the scene the run in DIR was started with
    elif args.scene is not None and Path(args.scene).is_dir():
        scene = load_scene(str(_scene_in_folder(args, Path(args.scene))), overrides=overrides)
    else:
        scene = load_scene(args.scene or DEFAULT_SCENE, overrides=overrides)
    out = Path(args.out) if args.out else Path(DEFAULT_OUT_ROOT) / scene.name
    return scene, out


def _scene_in_folder(args, folder):
    """The scene file of a folder given as SCENE: its scene.toml (the scene an `hmatddm run`
    stored there) or its only .toml file, said on stderr; InputError otherwise."""
    from ..errors import InputError
    from .runner import SCENE_FILE

    stored = folder / SCENE_FILE
    files = sorted(folder.glob("*.toml"))
    chosen = stored if stored.is_file() else (files[0] if len(files) == 1 else None)
    if chosen is None:
        listed = (f"it holds {len(files)} .toml files: {', '.join(p.name for p in files[:6])}"
                  f"{', ...' if len(files) > 6 else ''}; give one of them" if files else "it holds no .toml file")
        raise InputError(f"SCENE {str(folder)!r} is a folder, not a scene: {listed} (or an embedded scene name; "
                         "to continue a run in a folder: hmatddm run --out DIR --resume)")
    if not getattr(args, "quiet", False):
        print(f"hmatddm: {str(folder)!r} is a folder: running its scene file {chosen}", file=sys.stderr)
    return chosen


def _output_failed(out, error, args):
    """The message when an output could not be written during a run."""
    from .runner import CHECKPOINT_DIR
    from ..simulation import checkpoint as checkpoints

    kept = checkpoints.list_checkpoints(out / CHECKPOINT_DIR)
    if kept:
        where = (f"Every step up to step {kept[-1]} is checkpointed in {out / CHECKPOINT_DIR}; "
                 f"{'free disk space' if error.disk_full else 'make the folder writable'}, then continue with: "
                 f"{_resume_command(args, out)}")
    else:
        where = "No step was lost (none had finished); fix the folder or choose another --out and run again."
    print(f"hmatddm: error: {error}.\nhmatddm: {where}", file=sys.stderr)
    return EXIT_OUTPUT


def _interrupted(args, out, run):
    """The Ctrl-C message: names the newest checkpoint on disk (the step a resume starts
    from), not the last step computed (whose checkpoint may not have been written)."""
    from .runner import CHECKPOINT_DIR
    from ..simulation import checkpoint as checkpoints

    kept = checkpoints.list_checkpoints(out / CHECKPOINT_DIR)
    if kept:
        times = {int(r["step"]): r["time"] for r in run.records}
        when = f" (t = {times[kept[-1]]:g} s)" if kept[-1] in times else ""
        where = (f"the newest checkpoint is step {kept[-1]}{when} in {out / CHECKPOINT_DIR}. "
                 f"Continue from it with: {_resume_command(args, out)}")
    else:
        where = "before the first step finished (nothing to resume); run it again"
    print(f"\nhmatddm: interrupted; {where}", file=sys.stderr)
    return EXIT_INTERRUPTED


def _stopped_at_size_limit(args, out, run, error):
    from .runner import CHECKPOINT_DIR
    from ..simulation import checkpoint as checkpoints

    kept = checkpoints.list_checkpoints(out / CHECKPOINT_DIR)
    limit = 2 * error.limit
    where = (f"every step up to step {kept[-1]} is checkpointed; to continue with a higher limit: "
             f"{_resume_command(args, out)} --set numerics.max_elements={max(limit, error.elements)}"
             if kept else "no step had finished")
    print(f"hmatddm: stopped: {error} (numerics.max_elements); the outputs of the last finished step are in "
          f"{out}; {where}", file=sys.stderr)
    return EXIT_BAD_INPUT


def _say_undrained(scene):
    """The undrained constants a [poroelastic] section derives (ref. Eqs 5.19-5.21), on stderr."""
    from ..scene.build import undrained_rock

    rock = undrained_rock(scene)
    if rock is not None:
        print(f"hmatddm: poroelastic: {rock.summary()}; the run uses nu_u and B", file=sys.stderr)


def _run(args):
    import warnings

    from ..errors import ConvergenceError, InputError, NoInjectionWarning, OutputError, SizeLimitError
    from ..scene.preflight import check_scene

    if args.resume and args.overwrite:
        raise InputError("--resume continues the run in --out and --overwrite starts it over: give one of them, "
                         "not both")
    scene, out = _load_run_scene(args)
    size = check_scene(scene.data)  # values, geometry, size: every refusal before the engine loads
    pumped = ([cluster["rate"] for cluster in scene.data["cluster"]] if "well" not in scene.data
              else [row[1] for row in scene.data["well"]["schedule"]])
    if all(rate == 0.0 for rate in pumped):
        print("hmatddm: warning: every cluster has rate = 0 m^3/s: nothing drives the fractures, which only relax "
              "from numerics.initial_pressure", file=sys.stderr)
    if args.check:
        _say(args, json.dumps(scene.to_dict(), indent=1))
        if not args.quiet:
            print("hmatddm: estimate: " + "\nhmatddm: estimate: ".join(size.lines()), file=sys.stderr)
            _say_undrained(scene.data)
        return EXIT_OK
    warnings.simplefilter("ignore", NoInjectionWarning)  # said above, once
    from .runner import SceneRun

    run = SceneRun(scene, out, resume=args.resume, overwrite=args.overwrite, quiet=args.quiet)
    if not args.quiet:
        numerics = scene.numerics
        dt = (f"dt = auto from {numerics['first_time_step']:g} s" if numerics["time_step"] == "auto" else
              f"dt = {numerics['time_step']:g} s")
        print(f"hmatddm: running {scene.name!r} ({scene.source}) to t = {numerics['end_time']:g} s, "
              f"{dt}, backend {numerics['backend']}, into {out}", file=sys.stderr)
    try:
        summary = run.execute()
    except KeyboardInterrupt:
        return _interrupted(args, out, run)
    except SizeLimitError as error:
        return _stopped_at_size_limit(args, out, run, error)
    except OutputError as error:
        return _output_failed(out, error, args)
    except ConvergenceError as error:
        record = run.last_record
        where = f"after step {record['step']} (t = {record['time']:g} s)" if record is not None else "in the first step"
        print(f"hmatddm: did not converge {where}: {error}. The outputs of the last converged step are in {out}; "
              "try a smaller numerics.time_step, a lower numerics.relaxation or another numerics.scheme",
              file=sys.stderr)
        return EXIT_NOT_CONVERGED
    steps = [step for step in summary["steps"] if step.get("step", 1) > 0]  # step 0: the initial state
    last = steps[-1] if steps else None
    if not args.quiet:
        state = (f"t = {last['time']:g} s, {last['n_elements']} elements, {len(steps)} steps"
                 if last else "no step")
        reference = summary["reference"]
        comparison = ""
        errors = (reference[-1].get("relative_error") or {}) if reference and last else {}
        if any(value is not None for value in errors.values()):
            comparison = "; vs closed form: " + ", ".join(
                f"{key} {100 * value:+.1f}%" for key, value in errors.items() if value is not None)
        seconds = f"{summary['wall_seconds']:.1f} s"
        if run.resumed:
            seconds = f"{run.session_seconds:.1f} s ({summary['wall_seconds']:.1f} s in all, with the earlier sessions)"
        print(f"hmatddm: done in {seconds} ({state}{comparison}); outputs in {out}")
        print(f"hmatddm: {_budget_line(summary['steps'])}")
    return EXIT_OK


# ---------------------------------------------------------------------------------
# bench, render
# ---------------------------------------------------------------------------------

def _budget_line(steps):
    """The end-of-run line of the fluid budget: its worst residual against the fluid moved."""
    from ..simulation.records import worst_budget_residual

    worst = worst_budget_residual(steps)
    if worst is None:
        return "fluid budget: no record has one"
    residual, moved, step = worst
    return (f"fluid budget (volume at the reference density): worst residual {residual:+.2e} m^3 = "
            f"{abs(residual) / moved if moved > 0 else 0.0:.1e} of the fluid moved ({moved:.4g} m^3, step {step})")


def _bench(args):
    from .bench import format_table, run_bench

    rows = run_bench(quick=args.quick, stream=None if (args.quiet or args.json) else sys.stderr)
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print(format_table(rows))
    return EXIT_OK


def _render(args):
    from .runner import render_folder

    written = render_folder(args.dir, movie=args.movie)
    for path in written:
        _say(args, f"wrote {path}")
    return EXIT_OK


def _microseismic(args):
    from .catalogue import catalogue_for_folder

    paths, catalogue = catalogue_for_folder(args.dir, scene=args.scene)
    _say(args, f"{len(catalogue.events)} microseismic events")
    for path in paths:
        _say(args, f"wrote {path}")
    return EXIT_OK


# ---------------------------------------------------------------------------------
# parser and main
# ---------------------------------------------------------------------------------

def _sweep(args):
    from . import ensemble

    grid = ensemble.parameter_grid(length_exponent=args.length_exponent, density=args.density)
    rows = ensemble.sweep(grid, realizations=args.realizations, scheduler=args.scheduler, n_workers=args.workers)
    if args.json:
        print(json.dumps(rows, indent=1))
    else:
        print(ensemble.format_table(ensemble.summarize(rows)))
    return EXIT_OK


def build_parser():
    parser = argparse.ArgumentParser(prog="hmatddm",
                                     description="Hydraulic fractures with the displacement discontinuity "
                                                 "method, made fast by H-matrices (SI units throughout).",
                                     epilog="Exit codes: 0 ok, 1 check failed, 2 bad input, 3 did not converge, "
                                            "4 output not written (disk full or folder not writable; "
                                            "free space and continue with run --resume), 130 interrupted.")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scene and write summary.json, VTU/PVD, checkpoints and PNGs",
                         description="Run a scene (an embedded name, see `hmatddm scenes`, or a TOML file; "
                                     "default: the embedded 'default') and write DIR/summary.json, "
                                     "DIR/fractures.pvd with DIR/vtu/*.vtu, DIR/checkpoints, "
                                     "DIR/snapshots/*.png and DIR/history.png.",
                         epilog="Exit codes: 0 done, 2 bad input (a scene over numerics.max_elements or the "
                                "memory refused; a run growing past it stops with its last step checkpointed: "
                                "continue with --resume --set numerics.max_elements=...), "
                                "3 did not converge (the outputs of the last "
                                "converged step are written), 4 an output could not be written (disk full or "
                                "folder not writable: every finished step is checkpointed; free space and "
                                "continue with --resume), 130 interrupted (continue with --resume).")
    run.add_argument("scene", nargs="?", metavar="SCENE",
                     help="embedded scene name or .toml file (default: 'default'; with --resume and no SCENE, "
                          "the scene stored in DIR)")
    run.add_argument("--out", metavar="DIR", help=f"output folder (default: {DEFAULT_OUT_ROOT}/<scene name>)")
    run.add_argument("--backend", choices=("dense", "hmatrix"), help="override numerics.backend")
    run.add_argument("--resume", action="store_true", help="continue from the newest checkpoint in DIR")
    run.add_argument("--overwrite", action="store_true", help="start over in a DIR that already holds a run")
    run.add_argument("--set", action="append", metavar="KEY=VALUE",
                     help="override a scene value, e.g. --set numerics.end_time=10 (repeatable)")
    run.add_argument("--check", action="store_true",
                     help="check the scene, print it as JSON (every default filled in) and its size estimate "
                          "(elements, unknowns, memory, rough time; on stderr), and stop")
    run.add_argument("--quiet", action="store_true", help="no progress and no messages (errors still print)")
    run.set_defaults(handler=_run)

    scenes = sub.add_parser("scenes", help="list the embedded scenes (or print one as TOML)")
    scenes.add_argument("name", nargs="?", metavar="NAME", help="print this scene's TOML")
    scenes.add_argument("--json", action="store_true", help="print {name: description} as JSON")
    scenes.set_defaults(handler=_scenes)

    validate = sub.add_parser("validate", help="closed-form checks (Griffith, Sneddon) as a table")
    validate.add_argument("--json", action="store_true", help="print JSON instead of a table")
    validate.add_argument("--quiet", action="store_true", help="no progress lines (on stderr)")
    validate.set_defaults(handler=_validate)

    bench = sub.add_parser("bench", help="H-matrix against dense: build time, memory, matvec time, error")
    bench.add_argument("--quick", action="store_true", help="small sizes only (about 11 s of CPU time)")
    bench.add_argument("--json", action="store_true", help="print JSON instead of a table")
    bench.add_argument("--quiet", action="store_true", help="no progress")
    bench.set_defaults(handler=_bench)

    render = sub.add_parser("render", help="snapshots, profile pictures of every saved step and history plot of "
                                           "a finished or partial run (--movie: an animated GIF of the profiles)")
    render.add_argument("dir", metavar="DIR", help="the --out folder of `hmatddm run`")
    render.add_argument("--movie", action="store_true",
                        help="also write DIR/movie.gif, the profile pictures of the saved steps in turn")
    render.add_argument("--quiet", action="store_true", help="do not list the written files")
    render.set_defaults(handler=_render)
    microseismic = sub.add_parser("microseismic", help="event catalogue (events.csv) and map of a finished run "
                                                       "(ref. Ch. 7)")
    microseismic.add_argument("dir", metavar="DIR", help="the --out folder of `hmatddm run`")
    microseismic.add_argument("--scene", metavar="FILE", help="scene file or embedded name whose [microseismic] "
                                                              "section to use (default: the run's own scene)")
    microseismic.add_argument("--quiet", action="store_true", help="do not list the written files")
    microseismic.set_defaults(handler=_microseismic)
    sweep = sub.add_parser("sweep", help="natural-fracture network ensembles on Dask: intersection frequency "
                                         "(ref. Fig. 6.9) over a grid of densities and length exponents")
    sweep.add_argument("--density", type=float, nargs="+", default=[0.05, 0.1], help="areal densities, 1/m^2")
    sweep.add_argument("--length-exponent", type=float, nargs="+", default=[2.0, 3.0], help="power-law exponents a")
    sweep.add_argument("--realizations", type=int, default=10, help="seeds per grid point")
    sweep.add_argument("--scheduler", default=None, help="Dask scheduler address (default: a local cluster)")
    sweep.add_argument("--workers", type=int, default=None, help="local cluster workers (default: CPU count)")
    sweep.add_argument("--json", action="store_true", help="print JSON rows instead of a table")
    sweep.set_defaults(handler=_sweep)
    return parser


def _checkpoint_error():
    """CheckpointError, if its module was loaded (else nothing could have raised it, and
    InputError stands in)."""
    from ..errors import InputError

    module = sys.modules.get("hmatddm.simulation.checkpoint")
    return module.CheckpointError if module is not None else InputError


def main(argv=None):
    # numba's OpenMP workers spin-wait by default; on a shared 2-core machine that made one
    # small H-matvec take 9.5 ms instead of 0.45 ms (benchmarks/bench_dfn.py). The command
    # (not the library, which changes no environment variable) asks them to wait passively,
    # before numba starts its threads; an explicit OMP_WAIT_POLICY wins.
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    args = build_parser().parse_args(argv)
    from ..errors import ConvergenceError, InputError, OutputError

    try:
        return args.handler(args)
    except OutputError as exc:  # before CheckpointError: a checkpoint that cannot be written is an output error
        print(f"hmatddm: error: {exc}", file=sys.stderr)
        return EXIT_OUTPUT
    except (InputError, _checkpoint_error()) as exc:
        print(f"hmatddm: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except ConvergenceError as exc:
        print(f"hmatddm: did not converge: {exc}", file=sys.stderr)
        return EXIT_NOT_CONVERGED
    except KeyboardInterrupt:
        print("\nhmatddm: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())

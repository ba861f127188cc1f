"""``ddmm simulate``: a population on a scene into a netCDF dataset."""

from __future__ import annotations

import time

from ddmm.experiments.cli.options import (
    add_run_options,
    check_out_file,
    parse_types,
    population_from_args,
    scenes_from_args,
)

__all__ = ["register", "run_simulate"]


def register(sub) -> None:
    """Add ``ddmm simulate``."""
    p = sub.add_parser("simulate", help="simulate a population on a scene into a netCDF dataset")
    add_run_options(p, out_required=True)
    p.set_defaults(func=run_simulate)


def run_simulate(args) -> int:
    from ddmm.population import save_dataset, simulate
    out = check_out_file(args.out, inputs={"--scene": args.scene, "--sites": args.sites,
                                           "--population": args.population, "--indent": args.indent})
    pop, scenes = population_from_args(args), scenes_from_args(args)
    start = time.perf_counter()
    ds = simulate(pop, scenes, engine=args.engine, dt=None if args.dt is None else args.dt * 1e-3,
                  method=args.method, tolerance=args.tolerance, trials=args.trials, seed=args.seed,
                  no_shear=args.no_shear, afferent_types=parse_types(args.types), quiet=args.quiet,
                  scheduler=args.scheduler)
    save_dataset(ds, out)
    if not args.quiet:
        choice = f"; {ds.attrs['tolerance_choice']}" if "tolerance_choice" in ds.attrs else ""
        print(f"wrote {out} ({ds.sizes['afferent']} afferents, {ds.sizes['spike']} spikes{choice}; "
              f"wall time {time.perf_counter() - start:.1f} s)")
    return 0

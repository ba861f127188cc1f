"""``ddmm plan``: what a ``simulate`` run would compute and skip."""

from __future__ import annotations

from ddmm.experiments.cli.options import add_run_options, parse_types, population_from_args, scenes_from_args

__all__ = ["register", "run_plan"]


def register(sub) -> None:
    """Add ``ddmm plan``."""
    p = sub.add_parser("plan", help="print what a simulate run would compute and skip")
    add_run_options(p, out_required=False)
    p.set_defaults(func=run_plan)


def run_plan(args) -> int:
    from ddmm.population import plan_run
    from ddmm.population.runtime.memory import estimate_memory
    pop, scenes = population_from_args(args), scenes_from_args(args)
    the_plan = plan_run(pop, scenes, trials=args.trials, no_shear=args.no_shear, afferent_types=parse_types(args.types),
                        engine=args.engine, scheduler=args.scheduler)
    print(the_plan.describe(pop, scenes))
    dt, method = 1e-4 if args.dt is None else args.dt * 1e-3, args.method or "euler"  # simulate's defaults
    if args.tolerance is not None:
        from ddmm.population.runtime.step_choice import choose_setting

        row = choose_setting(args.tolerance, scenes[0].fs)
        print(f"tolerance {args.tolerance:g} pulses/s: dt={row['dt_ms']:g} ms, method={row['method']} "
              f"(measured mean SF error {row['sf_err_mean']:.3g} pulses/s)")
        dt, method = row["dt_ms"] * 1e-3, row["method"]
    try:
        print(estimate_memory(pop, scenes, the_plan, dt=dt, method=method, no_shear=args.no_shear, seed=args.seed,
                              scheduler=args.scheduler, quiet=args.quiet).describe())
    except ValueError as err:  # a step or sample rate simulate refuses: the plan above still holds
        print(f"memory: not estimated, simulate would refuse this run: {err}")
    return 0

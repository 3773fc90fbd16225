"""``plansim bench``: speed and memory on this machine (:mod:`plansim.bench`)."""

from __future__ import annotations

from plansim.cli.common import COMMANDS


def _cmd_bench(args) -> int:
    import numba

    from plansim.bench import main as bench_main

    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            raise ValueError(f"--threads {args.threads}: allowed 1 to {numba.config.NUMBA_NUM_THREADS}")
        numba.set_num_threads(args.threads)
    return bench_main(json_output=args.json, quick=args.quick)


def add_commands(sub) -> None:
    p = sub.add_parser("bench", help=COMMANDS["bench"],
                       description="Measure speed and memory on this machine (takes a few minutes)")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    p.add_argument("--quick", action="store_true", help="small sizes (seconds): checks the method, not the speed")
    p.add_argument("--threads", type=int, default=None, help="pin the kernel thread count (default: all cores)")
    p.set_defaults(func=_cmd_bench)

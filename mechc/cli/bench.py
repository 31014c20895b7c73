"""``mechc bench``: the speed-against-accuracy benchmark (CSV and charts)."""

from __future__ import annotations

from mechc.bench import speed_accuracy


def register(sub) -> None:
    p = sub.add_parser("bench", help="speed against accuracy benchmark (CSV + charts)",
                       description=speed_accuracy.__doc__.split("\n\n")[0])
    speed_accuracy.add_arguments(p)
    p.set_defaults(func=speed_accuracy.run_args)

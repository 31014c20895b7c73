"""Helical springs designed from a rate and a largest force: the wire and coils that make a
model spring (rate, rest length) a part one can buy or wind.

For rate k (N/mm) and largest force F (N, preload + k x travel), music wire of diameter d at
spring index C = D/d (mean coil diameter D) gives (Shigley, Ch. 10):

- active coils   n = G d^4 / (8 D^3 k)
- shear stress   tau = K_w 8 F D / (pi d^3), Wahl factor K_w = (4C - 1)/(4C - 4) + 0.615/C
- free length    L0 = (n + 1) d + 2 (D - d) for an extension spring (close-wound body, two
  machine hooks of inside diameter D - d); L0 = (n + 2) d + (1 + 0.15) F / k for a compression
  spring (squared and ground ends: solid length (n + 2) d, plus its largest deflection and
  Shigley's 15 % clash allowance)

The design takes the thinnest stocked wire for which some index C in 6..12 keeps
``S_sy / tau >= SPRING_SAFETY`` and n >= ``MIN_ACTIVE_COILS``, and among those indices the one
with the shortest free length. A force no stocked wire carries keeps the thickest wire at C = 6,
and the spring stress check (``mechc/passes/strength.py``) fails with the numbers.
"""

from __future__ import annotations

import math
from functools import lru_cache

from mechc.cells.materials import MUSIC_WIRE, SpringWire
from mechc.ir.mechanism import Coil

#: Spring index range D/d: below 6 the wire is hard to coil, above 12 the spring tangles.
INDEX_RANGE = (6, 12)
#: Factor of safety of the wire's torsional yield over its working stress (Shigley's design
#: examples ask n_s >= 1.2 for static service).
SPRING_SAFETY = 1.2
#: Fewest active coils a spring is wound with (Shigley: 3 <= N_a <= 15 for compression springs).
MIN_ACTIVE_COILS = 3.0


def wahl(c: float) -> float:
    """The Wahl factor: direct shear and coil curvature at spring index ``c``."""
    return (4 * c - 1) / (4 * c - 4) + 0.615 / c


def coil(d: float, c: float, rate: float, force: float, kind: str = "extension",
         wire: SpringWire = MUSIC_WIRE) -> Coil:
    """The spring of wire ``d`` at index ``c`` that has rate ``rate``, at force ``force``."""
    D = c * d
    n = wire.G * d ** 4 / (8 * D ** 3 * rate)
    tau = wahl(c) * 8 * force * D / (math.pi * d ** 3)
    if kind == "extension":
        free = (n + 1) * d + 2 * (D - d)
    else:
        free = (n + 2) * d + 1.15 * force / rate
    return Coil(d, D, n, free, force, tau, wire.torsional_yield(d) / SPRING_SAFETY, kind)


@lru_cache(maxsize=1 << 16)  # a design's amplifiers ask the same springs: asked once each
def design_coil(rate: float, force: float, kind: str = "extension",
                wire: SpringWire = MUSIC_WIRE) -> Coil:
    """The thinnest stocked wire (and then the shortest spring) whose stress at ``force`` keeps
    the safety factor, for an ``kind`` ("extension" or "compression") spring of rate ``rate``
    N/mm."""
    force = max(force, 1e-6)
    for d in wire.sizes:
        fits = [coil(d, c, rate, force, kind, wire)
                for c in range(INDEX_RANGE[0], INDEX_RANGE[1] + 1)]
        fits = [s for s in fits if s.stress <= s.allowable and s.active_coils >= MIN_ACTIVE_COILS]
        if fits:
            return min(fits, key=lambda s: (s.free_length, s.mean_diameter))
    return coil(wire.sizes[-1], INDEX_RANGE[0], rate, force, kind, wire)

"""The materials parts are made of: plates (bars, sliders, levers, rods), spring wire, pins.

Every number is a room-temperature handbook or data-sheet value, cited where it is defined, in
SI-derived units the rest of mechc uses: density kg/mm^3, moduli and strengths MPa (N/mm^2).
The plate material is a compile option (``--material``, default aluminium 6061-T6, whose density
is the one mechc always used); springs are music wire and pins steel dowels whatever the plate,
as they are bought parts.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """A plate material. ``strength`` is the tensile yield strength of a ductile material, or
    the tensile (breaking) strength of a brittle one (``brittle`` True), which then has no yield
    to design against."""

    name: str  # the --material name
    title: str  # what it is, with the temper or grade
    density: float  # kg/mm^3
    E: float  # Young's modulus, MPa
    strength: float  # MPa: tensile yield (ductile) or tensile strength (brittle)
    brittle: bool
    G: float | None  # shear modulus, MPa (where known; springs use the wire's)
    source: str  # where the numbers come from


MATERIALS: dict[str, Material] = {m.name: m for m in (
    # ASM Aerospace Specification Metals / MatWeb, "Aluminum 6061-T6; 6061-T651": density
    # 2.70 g/cm^3, modulus of elasticity 68.9 GPa, tensile yield strength 276 MPa, shear
    # modulus 26 GPa.
    Material("aluminium", "aluminium 6061-T6", 2.7e-6, 68_900.0, 276.0, False, 26_000.0,
             "ASM Aerospace Specification Metals / MatWeb: Aluminum 6061-T6; 6061-T651"),
    # MatWeb, "AISI 1018 Steel, cold drawn": density 7.87 g/cm^3, modulus of elasticity
    # 205 GPa, tensile yield strength 370 MPa, shear modulus 80 GPa.
    Material("steel", "mild steel AISI 1018, cold drawn", 7.87e-6, 205_000.0, 370.0, False,
             80_000.0, "MatWeb: AISI 1018 Steel, cold drawn"),
    # Evonik (Röhm) PLEXIGLAS GS cast acrylic sheet, product data sheet (ISO 527): density
    # 1.19 g/cm^3, modulus of elasticity 3300 MPa, tensile stress at break 80 MPa. Brittle:
    # designed against its tensile strength with a larger safety factor.
    Material("acrylic", "acrylic (PMMA), cast sheet", 1.19e-6, 3_300.0, 80.0, True, None,
             "Evonik PLEXIGLAS GS product data sheet"),
    # Ultimaker PLA technical data sheet (ISO 527, printed XY): density 1.24 g/cm^3, tensile
    # modulus 2346.5 MPa, tensile stress at yield 49.5 MPa.
    Material("pla", "PLA, 3D-printed (FDM, XY)", 1.24e-6, 2_346.5, 49.5, False, None,
             "Ultimaker PLA technical data sheet"),
)}

DEFAULT_MATERIAL = "aluminium"


def material(name: str) -> Material:
    """The material called ``name``; a KeyError names the known ones."""
    try:
        return MATERIALS[name]
    except KeyError:
        raise KeyError(f"unknown material {name!r}; known: {', '.join(MATERIALS)}") from None


@dataclass(frozen=True)
class SpringWire:
    """Spring wire: minimum tensile strength ``A / d^m`` (d in mm) and the torsional yield as a
    fraction of it."""

    title: str
    G: float  # shear modulus, MPa
    A: float  # MPa mm^m
    m: float
    yield_fraction: float  # torsional yield S_sy / S_ut
    sizes: tuple[float, ...]  # stocked wire diameters, mm
    source: str

    def tensile_strength(self, d: float) -> float:
        """Minimum tensile strength S_ut (MPa) of wire of diameter ``d`` mm."""
        return self.A / d ** self.m

    def torsional_yield(self, d: float) -> float:
        """Torsional yield S_sy (MPa) of wire of diameter ``d`` mm."""
        return self.yield_fraction * self.tensile_strength(d)


#: Music wire, ASTM A228 (Shigley's Mechanical Engineering Design, 9th ed., Table 10-4:
#: A = 2211 MPa mm^m, m = 0.145, valid 0.10-6.5 mm; Table 10-5: G = 81.7 GPa; Table 10-6: the
#: static allowable torsional stress of music-wire compression springs, without set removal,
#: 45 % of S_ut, taken here as the torsional yield S_sy). Sizes: the preferred metric wire
#: diameters of EN 10270-1 (0.10 to 6.0 mm). Every spring of a design is music wire, whatever
#: the plate material.
MUSIC_WIRE = SpringWire(
    "music wire ASTM A228", 81_700.0, 2211.0, 0.145, 0.45,
    (0.10, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22, 0.25, 0.28, 0.30, 0.32, 0.36, 0.40, 0.45, 0.50,
     0.56, 0.60, 0.63, 0.70, 0.80, 0.90, 1.00, 1.10, 1.20, 1.40, 1.60, 1.80, 2.00, 2.20, 2.50,
     2.80, 3.00, 3.20, 3.60, 4.00, 4.50, 5.00, 5.50, 6.00),
    "Shigley's Mechanical Engineering Design, Tables 10-4 to 10-6; EN 10270-1 sizes")

#: Pins (pivots, rod ends, slot pins) are steel dowels whatever the plate: AISI 1018 cold drawn
#: (above); their shear yield is taken as 0.577 of the tensile yield (von Mises).
PIN_MATERIAL = MATERIALS["steel"]
PIN_SHEAR_FRACTION = 0.577
#: Stocked dowel-pin diameters (ISO 2338), mm.
PIN_SIZES = (2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0)

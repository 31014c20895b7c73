"""Threshold logic generators (001 Chapter III): any function of up to three inputs as one
separator linkage plus a cam threshold linkage, synthesised and checked by program.

Main entry points: :func:`design_generator` (weights -> separator -> loop FJK -> cam, with design
checks and a vectorised kinematic model) and :func:`realise` (minimum multithreshold weights).
"""

from mechc.threshold.functions import (
    as_truth_table,
    function_value,
    npn_canonical,
    npn_class_ids,
    truth_table_from_fv,
)
from mechc.threshold.generator import (
    GeneratorDesign,
    KinematicState,
    design_generator,
    generator_realisation,
)
from mechc.threshold.weights import (
    Realisation,
    realise,
    realise_milp,
    realise_search,
    static_hazards,
    thresholds_for,
)

__all__ = [
    "GeneratorDesign",
    "KinematicState",
    "Realisation",
    "as_truth_table",
    "design_generator",
    "function_value",
    "generator_realisation",
    "npn_canonical",
    "npn_class_ids",
    "realise",
    "realise_milp",
    "realise_search",
    "static_hazards",
    "thresholds_for",
    "truth_table_from_fv",
]

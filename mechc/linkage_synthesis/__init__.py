"""Dimensional synthesis: the programs that find link lengths and pivots (``mechc synth``).

three_bar_gate the 3-bar AND/OR gate of ``000_…`` (closed form + numerical check)
mk_circles    M/K(/T)-circle precision-position synthesis of dyads and triads (``004_…``)
compatibility the compatibility-linkage method, a cross-check for 4-position dyads
defects       circuit/branch defects of the assembled four-bar or six-bar
adders        exact and approximate bar-linkage adders and their structural error (``002_…``)
harmonic      ideal and non-ideal harmonic transformers, homogeneous parameters (``002_…``)
"""

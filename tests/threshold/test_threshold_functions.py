"""FV numbering (001 §3.7.1) and NPN classes."""

from __future__ import annotations

import numpy as np

from mechc.threshold.functions import (
    as_truth_table,
    depends_on,
    function_value,
    input_matrix,
    is_unate,
    npn_canonical,
    npn_class_ids,
    table_fv,
    truth_table_from_fv,
)


def test_fv_of_the_chapter_iii_examples():
    # §3.8.1: minterms 0, 3, 4, 5, 7 give FV = 128 + 16 + 8 + 4 + 1 = 157, complement 98.
    tt = tuple(1 if m in (0, 3, 4, 5, 7) else 0 for m in range(8))
    assert function_value(tt) == 157
    assert table_fv(157) == (98, True)
    # §3.8.2: the full adder's sum, minterms 1, 2, 4, 7 -> 64 + 32 + 8 + 1 = 105.
    x = input_matrix(3)
    parity = tuple(int(v) for v in x.sum(1) % 2)
    assert function_value(parity) == 105
    assert table_fv(105) == (105, False)


def test_fv_round_trip_and_bit_order():
    for fv in range(256):
        assert function_value(truth_table_from_fv(fv)) == fv
    # TV_0 is the minterm x1'x2'x3' and carries 2**7; TV_7 (x1 x2 x3) carries 1.
    assert truth_table_from_fv(128) == (1, 0, 0, 0, 0, 0, 0, 0)
    assert truth_table_from_fv(1) == (0, 0, 0, 0, 0, 0, 0, 1)
    # x1 alone: on for minterms 4..7 -> FV 15 (Table IV row 15 has W = (1, 0, 0)).
    assert truth_table_from_fv(15) == tuple(int(v) for v in input_matrix(3)[:, 0])
    assert as_truth_table(15) == truth_table_from_fv(15)


def test_npn_class_counts_match_the_literature():
    # 14 NPN classes of 3-input functions (Table II's 13 plus the constants); 222 for 4 inputs.
    assert len(set(npn_class_ids(3).tolist())) == 14
    assert len(set(npn_class_ids(4).tolist())) == 222


def test_npn_canonical_is_invariant_under_the_group():
    rng = np.random.default_rng(0)
    x = input_matrix(3)
    for _ in range(40):
        tt = tuple(int(v) for v in rng.integers(0, 2, 8))
        perm = rng.permutation(3)
        neg = rng.integers(0, 2, 3)
        g = (x[:, perm] ^ neg) @ np.array([4, 2, 1])
        moved = tuple(int(tt[i]) for i in g)
        if rng.integers(0, 2):
            moved = tuple(1 - v for v in moved)
        assert npn_canonical(moved) == npn_canonical(tt)
        assert function_value(npn_canonical(tt)) == npn_class_ids(3)[function_value(tt)]


def test_unate_and_support():
    assert is_unate(truth_table_from_fv(23))  # majority
    assert not is_unate(truth_table_from_fv(105))  # parity
    assert depends_on(truth_table_from_fv(3)) == [0, 1]  # FV 3 = x1 x2

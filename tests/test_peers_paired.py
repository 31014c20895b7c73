"""The paired peer measure (``mechc.bench.peers.alternate``): every function timed once per
round, the order turned each round, so a change of load between rounds is not always paid by
the same side; the ratios are per round."""

from __future__ import annotations

import statistics

from mechc.bench import peers


class FakeClock:
    """A clock the timed functions advance by known amounts: the measure must report them."""

    def __init__(self):
        self.now = 0.0
        self.calls: list[str] = []

    def __call__(self) -> float:
        return self.now

    def work(self, name: str, seconds: float):
        def run():
            self.calls.append(name)
            self.now += seconds
        return run


def test_each_function_is_timed_once_per_round_in_turned_order():
    clock = FakeClock()
    fns = {"a": clock.work("a", 1.0), "b": clock.work("b", 2.0), "c": clock.work("c", 4.0)}
    out = peers.alternate(fns, rounds=4, clock=clock)  # one call each per round
    assert out == {"a": [1.0] * 4, "b": [2.0] * 4, "c": [4.0] * 4}
    assert clock.calls == list("abc" "bca" "cab" "abc")


def test_a_burst_of_load_in_one_round_does_not_move_the_median():
    """Round 2's mechc measure is slowed 3x (a burst of load): its ratio falls, the median of
    the rounds stays the undisturbed ratio, 5."""
    slow = {2}
    clock = FakeClock()
    rnd = [0]

    def mechc():
        clock.now += 0.01 * (3 if rnd[0] in slow else 1)

    def peer():
        clock.now += 0.05
        rnd[0] += 1

    secs = peers.alternate({"mechc": mechc, "mechc reduced": mechc, "pylinkage": peer},
                           rounds=7, clock=clock)
    pr = peers.Paired.of(secs)
    assert len(pr.checked) == 7
    assert min(pr.checked) < 2.0  # the disturbed round is seen ...
    assert abs(statistics.median(pr.checked) - 5.0) < 1e-9  # ... and left out
    assert abs(statistics.median(pr.reduced) - 5.0) < 1e-9


def test_inner_calls_keep_each_rounds_least_disturbed_time():
    clock = FakeClock()
    times = iter([3.0, 1.0, 2.0, 5.0, 4.0, 6.0])

    def f():
        clock.now += next(times)

    assert peers.alternate({"f": f}, rounds=2, inner=3, clock=clock) == {"f": [1.0, 4.0]}
